#pragma once
// Rigid joints of the stent frame by master–slave elimination (issue 9;
// DESIGN.md §8: every strut and connector owns its end nodes).
//
// A joint keeps equal positions and equal incremental rotations,
// Λ_a Λ_a0ᵀ = Λ_b Λ_b0ᵀ (the reference kink is kept), and never couples the
// Hermite tangents. With the spatial update Λ ← exp(S(Δθ)) Λ (beam_term.hpp)
// both conditions are linear and exact in the DOFs: equal position
// displacements and equal rotation increments Δθ_a = Δθ_b keep
// Λ_a Λ_a0ᵀ = Λ_b Λ_b0ᵀ for any number of steps. So the slave node simply
// shares its master's position and rotation DOF numbers: the assembly sums
// both nodes' contributions into one set of equations (elimination), and
// trial() gives both triads the same increment. Nodes joined in chains
// (a crown with a connector) form one group whose master is the lowest node.
#include "solver/beams/beam_term.hpp"

#include <array>
#include <string>
#include <vector>

namespace stentsim::solver::beams {

struct JointMap {
  std::vector<int> master;  // master[n] = the group's master node (n itself for masters and free nodes)
  bool is_slave(int node) const { return master.at(node) != node; }
};

/// Groups the joint pairs. Throws InputError naming `where` and the pair when
/// a node is out of range or the two reference positions differ by more than
/// `position_tolerance` (mm).
JointMap make_joint_map(const BeamBodyDefinition& body, const std::vector<std::array<int, 2>>& joints,
                        const std::string& where, double position_tolerance = 1e-9);

/// DOF numbers from `first` with every slave's position and rotation DOFs
/// those of its master; tangents (and middle-node rotations) stay per node.
/// Returns the next free number in `next`.
std::vector<BeamNodeDofs> number_joined_beam_dofs(const BeamBodyDefinition& body, const JointMap& joints,
                                                  GlobalDof first, GlobalDof* next);

/// A condition (Dirichlet, direction constraint, load) on a joint acts on its
/// master node; on a slave node it is an error: throws InputError naming
/// `where`, the node and its master.
void require_master_node(const JointMap& joints, int node, const std::string& where);

}  // namespace stentsim::solver::beams
