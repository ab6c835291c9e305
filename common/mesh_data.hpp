#pragma once
// Plain mesh data as the stages exchange it through VTU/VTP files: points,
// cells by VTK cell type, named point and cell arrays. No VTK header here;
// vtk_io.cpp is the adapter.
#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace stentsim {

/// VTK cell type codes used in the project (values as in vtkCellType.h).
enum class CellType : std::uint8_t {
  vertex = 1,
  line = 3,
  polyline = 4,
  triangle = 5,
  quad = 9,
  tetra = 10,
  hexahedron = 12,
  quadratic_edge = 21,
  quadratic_triangle = 22,
  quadratic_tetra = 24,
};

/// Number of nodes of a fixed-size cell type (0 for polyline).
int nodes_per_cell(CellType t);

/// A named array: `components` values per point or cell, stored row by row.
struct DataArray {
  int components = 1;
  std::vector<double> values;
  std::size_t tuples() const { return components ? values.size() / static_cast<std::size_t>(components) : 0; }
  double at(std::size_t tuple, int c = 0) const { return values[tuple * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)]; }
};

struct MeshData {
  std::vector<Eigen::Vector3d> points;
  std::vector<CellType> cell_types;
  std::vector<std::int64_t> cell_offsets{0};  // cell i has connectivity[offsets[i], offsets[i+1])
  std::vector<std::int64_t> connectivity;
  std::map<std::string, DataArray> point_data;
  std::map<std::string, DataArray> cell_data;
  /// Small per-file facts (units, provenance) written as VTK field data.
  std::map<std::string, std::string> field_text;

  std::size_t num_cells() const { return cell_types.size(); }
  void add_cell(CellType t, const std::vector<std::int64_t>& nodes);
  std::vector<std::int64_t> cell(std::size_t i) const;
};

/// Writes an unstructured grid (.vtu, binary appended, compressed). Atomic.
void write_vtu(const std::string& file, const MeshData& mesh);
/// Writes poly data (.vtp): lines and polylines as lines, triangles/quads as polys. Atomic.
void write_vtp(const std::string& file, const MeshData& mesh);
/// Reads a .vtu. Throws InputError naming the file when it is not one, when VTK's
/// reader crashes on it (it is read in a child process first: check_vtk_xml_file)
/// or when a cell refers past the points.
MeshData read_vtu(const std::string& file);
/// Reads a .vtp (lines become polylines, polygons triangles/quads); errors as read_vtu.
MeshData read_vtp(const std::string& file);
/// VTK 9.1's XML readers crash inside their own parser on some damaged files, past
/// what a check before them can see: the file (.vtu or .vtp) is read in a child
/// process first, and a crash or a hang there is an InputError naming the file.
void check_vtk_xml_file(const std::string& file);

}  // namespace stentsim
