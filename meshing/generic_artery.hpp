#pragma once
// The generic artery of paper Case 1 (Section 4.1; DESIGN.md §5): a straight
// tube along +z, centred at the origin like the straight device (z from
// −length/2 to length/2), media inside adventitia, meshed with structured trilinear hex8.
#include "common/mesh_data.hpp"
#include "common/summary.hpp"

namespace stentsim::meshing {

struct GenericArterySpec {
  double length = 11.0;               // mm
  double outer_diameter = 2.8;        // mm
  double media_thickness = 0.22;      // mm (Holzapfel 2005 ratio, DESIGN §5)
  double adventitia_thickness = 0.38; // mm
  int elements_around = 48;
  int elements_along = 36;
  int elements_media = 2;             // through the thickness
  int elements_adventitia = 2;
};

/// Throws InputError naming the field when the spec cannot be meshed.
void validate(const GenericArterySpec& s);

/// Hex8 volume cells (Layer media/adventitia) plus quad4 boundary faces
/// (FaceGroup endothelium, outer_wall, proximal_cut, distal_cut) with
/// outward-pointing normals. Default spec: 8,880 nodes, 26,640 DOFs.
MeshData generic_artery_mesh(const GenericArterySpec& s);

/// Writes the mesh and records its counts in `summary`.
void write_generic_artery(const GenericArterySpec& s, const std::string& artery_vtu, Summary& summary);

}  // namespace stentsim::meshing
