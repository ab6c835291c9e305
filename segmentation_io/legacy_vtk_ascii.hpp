#pragma once
// Legacy VTK POLYDATA in ASCII, read by stentsim itself: VTK 9.1's legacy
// reader crashes on damaged ASCII files (a file cut inside its cell list reads
// past the end in vtkDataReader::ReadString; found by fuzzing), so every count
// here is checked against what the file holds before it is used. Points,
// POLYGONS and TRIANGLE_STRIPS are read (the classic "n size" lists and the
// 5.1 OFFSETS/CONNECTIVITY form); VERTICES and LINES are skipped; attribute
// sections (POINT_DATA, CELL_DATA, FIELD, METADATA) end the geometry.
#include <filesystem>
#include <optional>

#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::segmentation {

/// The triangles (polygons fanned, strips split) of an ASCII legacy POLYDATA
/// file; nothing for a BINARY one (VTK reads those). InputError naming the file
/// and the section for anything malformed.
std::optional<TriSurface> read_legacy_vtk_ascii(const std::filesystem::path& file);

}  // namespace stentsim::segmentation
