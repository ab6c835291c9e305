#pragma once
// Nodal direction constraints enforced exactly with Lagrange multipliers λ
// (their own DOFs in the global vector):
//   R_u += Pᵀ λ,  R_λ = P (u − 0),
// so Pᵀλ is the reaction force. Two kinds (the stent file's fixation flags,
// device_gen/stent_model.hpp; paper Section 2.2; DESIGN.md §5):
//  - along d  ("moves only along d", the radial fixations): P = [p₁ p₂]ᵀ with
//    p₁, p₂ ⊥ d orthonormal, two multipliers; the reaction is normal to d.
//  - normal to d ("fixed along d", the axial fixation): P = dᵀ, one
//    multiplier; the node keeps d·u = 0 and is free in the plane ⊥ d (so it
//    can expand radially); the reaction is along d.
// The tangent [[0, Pᵀ], [P, 0]] is symmetric, indefinite: the linear solver
// must accept saddle points (direct LU does).
#include "solver/terms/term.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <string>
#include <vector>

namespace stentsim::solver::beams {

class DirectionConstraintTerm : public Term {
 public:
  enum class Kind { along, normal };
  /// "Moves only along `direction`" (Kind::along, two multipliers).
  DirectionConstraintTerm(std::string name, std::array<GlobalDof, 3> position_dofs, Eigen::Vector3d direction,
                          std::array<GlobalDof, 2> multiplier_dofs);
  /// "Fixed along `direction`": d·u = 0 (Kind::normal, one multiplier).
  DirectionConstraintTerm(std::string name, std::array<GlobalDof, 3> position_dofs, Eigen::Vector3d direction,
                          GlobalDof multiplier_dof);
  std::string name() const override { return name_; }
  void assemble(const SystemState& state, Assembler& out) override;
  /// The reaction force on the node at `u` (Pᵀλ).
  Eigen::Vector3d reaction(const Eigen::VectorXd& u) const;
  Kind kind() const { return kind_; }
  /// Multipliers per node of a kind (2 along, 1 normal).
  static int multiplier_count(Kind k) { return k == Kind::along ? 2 : 1; }

 private:
  std::string name_;
  Kind kind_;
  std::array<GlobalDof, 3> pos_;
  std::vector<GlobalDof> lam_;
  Eigen::Matrix<double, Eigen::Dynamic, 3> P_;  // one row per multiplier
};

}  // namespace stentsim::solver::beams
