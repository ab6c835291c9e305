#pragma once
// Reads the stent stage's beam model (stent.vtu, format "stentsim stent 1",
// device_gen/stent_mesh.hpp) into a beam body definition plus the joint and
// fixation sets the solver couples (DESIGN.md §8: every strut and connector
// owns its end nodes; joints couple positions and incremental rotations).
// Only the file format is shared with device_gen, not code (DESIGN.md §2).
#include "common/mesh_data.hpp"
#include "solver/beams/beam_term.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace stentsim::solver::beams {

struct StentBeams {
  BeamBodyDefinition body;
  std::vector<std::array<int, 2>> joints;  // node pairs: equal positions, Λ_a Λ_a0ᵀ = Λ_b Λ_b0ᵀ
  struct Fixation {
    int node;
    Eigen::Vector3d direction;
    bool axial;  // false: moves only along `direction`; true: fixed along `direction`
  };
  std::vector<Fixation> fixations;
  /// Per beam element: its ring (struts), −1 for connectors; empty when the
  /// file has no MemberKind/Ring arrays (the stent QoI needs them).
  std::vector<int> element_ring;
};

/// Builds the body from a stent mesh with an elastic circular section of
/// radius SectionRadius (one value for all beams), Young's modulus E and shear
/// modulus G. `where` names the file in errors (InputError).
StentBeams stent_beams_from_mesh(const MeshData& mesh, double E, double G, const std::string& where);

}  // namespace stentsim::solver::beams
