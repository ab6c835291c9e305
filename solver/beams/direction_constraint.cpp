#include "solver/beams/direction_constraint.hpp"

#include "common/error.hpp"

#include <cmath>
#include <utility>

namespace stentsim::solver::beams {

DirectionConstraintTerm::DirectionConstraintTerm(std::string name, std::array<GlobalDof, 3> position_dofs,
                                                 Eigen::Vector3d direction, std::array<GlobalDof, 2> multiplier_dofs)
    : name_(std::move(name)), pos_(position_dofs), lam_(multiplier_dofs) {
  const double n = direction.norm();
  if (!(n > 0.0) || !std::isfinite(n))
    throw InputError("direction constraint '" + name_ + "': direction must be a non-zero finite vector");
  const Eigen::Vector3d d = direction / n;
  // p₁: the coordinate axis least aligned with d, orthogonalized.
  Eigen::Index i;
  d.cwiseAbs().minCoeff(&i);
  Eigen::Vector3d p1 = Eigen::Vector3d::Unit(i) - d[i] * d;
  p1.normalize();
  const Eigen::Vector3d p2 = d.cross(p1);
  P_.row(0) = p1.transpose();
  P_.row(1) = p2.transpose();
}

void DirectionConstraintTerm::assemble(const SystemState& state, Assembler& out) {
  if (state.rank != 0) return;
  std::array<GlobalDof, 5> d{pos_[0], pos_[1], pos_[2], lam_[0], lam_[1]};
  Eigen::Vector3d u;
  Eigen::Vector2d l;
  for (int i = 0; i < 3; ++i) u[i] = pos_[i] >= 0 ? state.u[pos_[i]] : 0.0;
  for (int i = 0; i < 2; ++i) l[i] = lam_[i] >= 0 ? state.u[lam_[i]] : 0.0;
  Eigen::Matrix<double, 5, 1> R;
  R.head<3>() = P_.transpose() * l;
  R.tail<2>() = P_ * u;
  Eigen::Matrix<double, 5, 5> K = Eigen::Matrix<double, 5, 5>::Zero();
  K.topRightCorner<3, 2>() = P_.transpose();
  K.bottomLeftCorner<2, 3>() = P_;
  out.add(d, R, K);
}

Eigen::Vector3d DirectionConstraintTerm::reaction(const Eigen::VectorXd& u) const {
  Eigen::Vector2d l;
  for (int i = 0; i < 2; ++i) l[i] = lam_[i] >= 0 ? u[lam_[i]] : 0.0;
  return P_.transpose() * l;
}

}  // namespace stentsim::solver::beams
