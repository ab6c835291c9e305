#pragma once
// The balloon mesh: a hollow cylinder along the device axis, one layer of
// linear hex8 through the wall (DESIGN.md §5).
//
// balloon.vtu format (read by the solver):
// - hexahedron cells (VTK 12) with CellRole = 0 come first: node order
//   (inner, outer, outer, inner) at the proximal ring then the same at the
//   distal ring, i.e. local axes radial x circumferential = axial (positive
//   Jacobian). Cell data Radial, Circumferential, Longitudinal: the local
//   material directions at the element centre (balloon fibre families).
// - quad cells (VTK 9) are the tagged faces, each the VTK face of its hex
//   (outward normal of the wall): CellRole 1 = inner (pressure), 2 = outer
//   (contact), 3 = proximal end, 4 = distal end (springs). ParentCell is the
//   hex index, ParentFace the VTK local face index (0..5).
// - point data NodeTag: bit flags 1 inner, 2 outer, 4 proximal end, 8 distal end.
// - field data: format, units, counts.
#include "common/mesh_data.hpp"
#include "device_gen/balloon_design.hpp"
#include "device_gen/device_axis.hpp"

namespace stentsim::device_gen {

enum BalloonCellRole { kBalloonSolid = 0, kBalloonInner = 1, kBalloonOuter = 2, kBalloonProximal = 3, kBalloonDistal = 4 };
enum BalloonNodeTag { kNodeInner = 1, kNodeOuter = 2, kNodeProximal = 4, kNodeDistal = 8 };

/// Builds the balloon along `axis` (whose length must equal the design length).
MeshData build_balloon_mesh(const BalloonDesign& design, const DeviceAxis& axis);

}  // namespace stentsim::device_gen
