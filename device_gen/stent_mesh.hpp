#pragma once
// stent.vtu: the stent model as the solver reads it (DESIGN.md §1, §8).
//
// Format "stentsim stent 1" (units mm):
// - points: every node; point data
//     TriadE1, TriadE2, TriadE3  reference triad (e1 along the beam, e2 radial
//                                outward, e3 = e1 x e2), orthonormal
//     NodeKind                   0 = Hermite end node (9 DOFs: position,
//                                rotation, tangent), 1 = middle node (3
//                                rotational DOFs)
// - cells, told apart by cell data CellRole:
//     0 beam    quadratic edge (VTK 21): end node, end node, middle node;
//               one Simo-Reissner Hermite beam element (ElementType 1)
//     1 joint   line (VTK 3): a node pair (a, b) at the same position whose
//               rotations are coupled rigidly, Lambda_a Lambda_a0^T =
//               Lambda_b Lambda_b0^T, positions equal; tangents not coupled
//     2 radial fixation  vertex (VTK 1): the node moves only along Direction
//                         (the local radial direction, paper 2.2)
//     3 axial fixation   vertex: the node is fixed along Direction (the axis
//                         tangent; straight stents only)
// - cell data for beams (other cells carry -1 or 0): ElementType (1),
//   Member (strut/connector index), MemberKind (0 strut, 1 connector), Ring
//   (strut: ring; connector: the gap ring -> ring+1), SectionRadius (mm),
//   MaterialId; Direction (3 components, fixations only).
// - field data: format, units, counts and the design.
#include "common/mesh_data.hpp"
#include "device_gen/stent_design.hpp"
#include "device_gen/stent_model.hpp"

namespace stentsim::device_gen {

enum StentCellRole { kStentBeam = 0, kStentJoint = 1, kStentRadialFixation = 2, kStentAxialFixation = 3 };
inline constexpr int kSimoReissnerHermite3 = 1;

MeshData stent_to_mesh(const StentModel& model, const StentDesign& design);

}  // namespace stentsim::device_gen
