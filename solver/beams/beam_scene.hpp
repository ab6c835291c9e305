#pragma once
// Beam bodies and beam node selections as scene files name them (issue 8;
// examples/beam_rollup.yaml, beam_bend45.yaml). A body with `beam:` instead
// of `mesh:` is either read from the stent stage's stent.vtu (stent_body.hpp)
// or generated:
//   beam:
//     generate: {type: line, start: [0,0,0], end: [10,0,0], elements: 16, d2: [0,1,0]}
//     generate: {type: arc, center: [100,0,0], start: [0,0,0], normal: [0,0,-1], angle_deg: 45, elements: 8}
//     file: stent.vtu                      (section radius from the file)
//     interpolation: hermite3 | lagrange2  (generated only; default hermite3)
//     section: {radius: R} | {A, A2, A3, I2, I3, IT}   (generated only)
//     E: 1e4 MPa
//     G: 5e3 MPa
//     material: stent                      (instead of E, G: the App. C stent preset,
//                                           E 380000, G 190000, E_ep 64000 MPa, M_y0 0.08 N mm,
//                                           elasto-plastic bending; the section radius stays the
//                                           file's / the section's, R = 0.06 mm for the stent stage)
//     plastic: {E_ep: 64000 MPa, M_y0: 0.08}   (with E, G: elasto-plastic bending, circular sections)
//     joints: rigid | none                 (stent files: rigid joints by master–slave DOF
//                                           sharing, rigid_joints.hpp; default rigid)
// Generated node numbering (as tests/solver/beam_test_bodies.hpp): end nodes
// 0..N along the curve (0 = start, N = end), then Hermite middle nodes.
// Arc triads: d1 = tangent (normal × radial), d2 = outward radial, d3 = d1 × d2.
// Node selectors: `first` | `last` | `fixations` (the stent file's fixation
// nodes) | `joints` (the master node of every joint group, e.g. the crowns of
// a ring) | {point: [x, y, z], tolerance: t} (the end node at that point; on
// a joint its master node) | {index: [n, ...]} (node numbers as in the file;
// a condition on a joint's slave node is an error naming it).
#include "common/config.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/rigid_joints.hpp"
#include "solver/beams/stent_body.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace stentsim::solver::beams {

struct BeamBodyDesc {
  BeamBodyDefinition body;
  std::vector<std::array<int, 2>> joints;           // from a stent file
  std::vector<StentBeams::Fixation> fixations;      // from a stent file
  std::vector<int> element_ring;                    // from a stent file: ring per element, −1 connectors
  std::string source;                               // file name or generator, for logs and the summary
  bool couple_joints = true;                        // `joints: rigid` (default) or `none`
  JointMap joint_map;                               // identity when no joints are coupled
  /// DOF numbers from `first`: joined (master–slave) when joints are coupled.
  std::vector<BeamNodeDofs> number_dofs(GlobalDof first, GlobalDof* next) const;
};

/// Reads the `beam:` map of a body (validation errors name file:line:key).
BeamBodyDesc read_beam_body(ConfigMap& beam);

struct BeamNodeSelector {
  enum class Kind { first, last, fixations, joints, point, index } kind = Kind::last;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  std::vector<int> indices;  // Kind::index
  double tolerance = -1.0;  // < 0: 1e-6 × body size
  std::string describe() const;
};

/// Reads `cfg[key]`: a word (first, last, fixations, joints), {point, tolerance} or {index}.
BeamNodeSelector read_beam_node_selector(ConfigMap& cfg, const std::string& key);

/// Selected nodes (end nodes only); empty when nothing matches. `index`
/// selections are returned as given (out-of-range numbers throw InputError);
/// conditions check them with require_master_node.
std::vector<int> select_beam_nodes(const BeamBodyDesc& body, const BeamNodeSelector& s);

/// Tip rotation angle accumulated over load steps: the rotation vector of
/// Λ Λ₀ᵀ is defined up to multiples of 2π along its axis; `previous` (the
/// last step's vector) picks the branch, so a roll-up reads 2π, not 0.
Eigen::Vector3d unwrap_rotation_vector(const Eigen::Quaterniond& relative, const Eigen::Vector3d& previous);

}  // namespace stentsim::solver::beams
