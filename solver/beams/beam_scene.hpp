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
// Generated node numbering (as tests/solver/beam_test_bodies.hpp): end nodes
// 0..N along the curve (0 = start, N = end), then Hermite middle nodes.
// Arc triads: d1 = tangent (normal × radial), d2 = outward radial, d3 = d1 × d2.
// Node selectors: `first` | `last` | `fixations` (the stent file's fixation
// nodes) | {point: [x, y, z], tolerance: t} (the end node at that point).
#include "common/config.hpp"
#include "solver/beams/beam_term.hpp"
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
  std::string source;                               // file name or generator, for logs and the summary
};

/// Reads the `beam:` map of a body (validation errors name file:line:key).
BeamBodyDesc read_beam_body(ConfigMap& beam);

struct BeamNodeSelector {
  enum class Kind { first, last, fixations, point } kind = Kind::last;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double tolerance = -1.0;  // < 0: 1e-6 × body size
  std::string describe() const;
};

/// Reads `cfg[key]`: a word (first, last, fixations) or {point, tolerance}.
BeamNodeSelector read_beam_node_selector(ConfigMap& cfg, const std::string& key);

/// Selected nodes (end nodes only); empty when nothing matches.
std::vector<int> select_beam_nodes(const BeamBodyDesc& body, const BeamNodeSelector& s);

/// Tip rotation angle accumulated over load steps: the rotation vector of
/// Λ Λ₀ᵀ is defined up to multiples of 2π along its axis; `previous` (the
/// last step's vector) picks the branch, so a roll-up reads 2π, not 0.
Eigen::Vector3d unwrap_rotation_vector(const Eigen::Quaterniond& relative, const Eigen::Vector3d& previous);

}  // namespace stentsim::solver::beams
