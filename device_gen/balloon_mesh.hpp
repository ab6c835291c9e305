#pragma once
// The balloon mesh: a hollow cylinder along the device axis, one layer of
// linear hex8 through the wall (DESIGN.md §5).
//
// balloon.vtu format (read by the solver):
// Tags follow common/mesh_tags.hpp, as artery.vtu does:
// - hexahedron cells (VTK 12) with Layer = balloon_wall, FaceGroup = 0 come first: node order
//   (inner, outer, outer, inner) at the proximal ring then the same at the
//   distal ring, i.e. local axes radial x circumferential = axial (positive
//   Jacobian). Cell data Radial, Circumferential, Longitudinal: the local
//   material directions at the element centre (balloon fibre families).
// - quad cells (VTK 9) are the tagged faces, each the VTK face of its hex
//   (outward normal of the wall), Layer = 0 and FaceGroup = balloon_inner
//   (pressure), balloon_outer (contact), balloon_end_proximal,
//   balloon_end_distal (springs). ParentCell is the hex index, ParentFace the
//   VTK local face index (0..5).
// - point data NodeTag: bit flags 1 inner, 2 outer, 4 proximal end, 8 distal end.
// - field data: format, units, counts.
#include "common/mesh_data.hpp"
#include "common/mesh_tags.hpp"
#include "device_gen/balloon_design.hpp"
#include "device_gen/device_axis.hpp"

namespace stentsim::device_gen {

enum BalloonNodeTag { kNodeInner = 1, kNodeOuter = 2, kNodeProximal = 4, kNodeDistal = 8 };

/// Builds the balloon along `axis` (whose length must equal the design length).
MeshData build_balloon_mesh(const BalloonDesign& design, const DeviceAxis& axis);

}  // namespace stentsim::device_gen
