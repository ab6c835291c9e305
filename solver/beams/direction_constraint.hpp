#pragma once
// "This node moves only along direction d" (the stent's fixation nodes move
// only radially, paper Section 2.2; DESIGN.md §5), enforced exactly with two
// Lagrange multipliers λ (their own DOFs in the global vector):
//   R_u += Pᵀ λ,  R_λ = P (u − 0),  P = [p₁ p₂]ᵀ, p₁, p₂ ⊥ d orthonormal,
// so the node's displacement has no component normal to d, and Pᵀλ is the
// reaction force (normal to d). The tangent [[0, Pᵀ], [P, 0]] is symmetric,
// indefinite: the linear solver must accept saddle points (direct LU does).
#include "solver/terms/term.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <string>

namespace stentsim::solver::beams {

class DirectionConstraintTerm : public Term {
 public:
  DirectionConstraintTerm(std::string name, std::array<GlobalDof, 3> position_dofs, Eigen::Vector3d direction,
                          std::array<GlobalDof, 2> multiplier_dofs);
  std::string name() const override { return name_; }
  void assemble(const SystemState& state, Assembler& out) override;
  /// The reaction force on the node at `u` (Pᵀλ).
  Eigen::Vector3d reaction(const Eigen::VectorXd& u) const;

 private:
  std::string name_;
  std::array<GlobalDof, 3> pos_;
  std::array<GlobalDof, 2> lam_;
  Eigen::Matrix<double, 2, 3> P_;
};

}  // namespace stentsim::solver::beams
