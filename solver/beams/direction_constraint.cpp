#include "solver/beams/direction_constraint.hpp"

#include "common/error.hpp"

#include <cmath>
#include <utility>

namespace stentsim::solver::beams {

namespace {
Eigen::Vector3d unit_direction(const Eigen::Vector3d& direction, const std::string& name) {
  const double n = direction.norm();
  if (!(n > 0.0) || !std::isfinite(n))
    throw InputError("direction constraint '" + name + "': direction must be a non-zero finite vector");
  return direction / n;
}
}  // namespace

DirectionConstraintTerm::DirectionConstraintTerm(std::string name, std::array<GlobalDof, 3> position_dofs,
                                                 Eigen::Vector3d direction, std::array<GlobalDof, 2> multiplier_dofs)
    : name_(std::move(name)), kind_(Kind::along), pos_(position_dofs), lam_(multiplier_dofs.begin(), multiplier_dofs.end()) {
  const Eigen::Vector3d d = unit_direction(direction, name_);
  // p₁: the coordinate axis least aligned with d, orthogonalized.
  Eigen::Index i;
  d.cwiseAbs().minCoeff(&i);
  Eigen::Vector3d p1 = Eigen::Vector3d::Unit(i) - d[i] * d;
  p1.normalize();
  const Eigen::Vector3d p2 = d.cross(p1);
  P_.resize(2, 3);
  P_.row(0) = p1.transpose();
  P_.row(1) = p2.transpose();
}

DirectionConstraintTerm::DirectionConstraintTerm(std::string name, std::array<GlobalDof, 3> position_dofs,
                                                 Eigen::Vector3d direction, GlobalDof multiplier_dof)
    : name_(std::move(name)), kind_(Kind::normal), pos_(position_dofs), lam_{multiplier_dof} {
  P_.resize(1, 3);
  P_.row(0) = unit_direction(direction, name_).transpose();
}

void DirectionConstraintTerm::assemble(const SystemState& state, Assembler& out) {
  if (state.rank != 0) return;
  const Eigen::Index m = P_.rows();
  std::vector<GlobalDof> d{pos_[0], pos_[1], pos_[2]};
  d.insert(d.end(), lam_.begin(), lam_.end());
  Eigen::Vector3d u;
  Eigen::VectorXd l(m);
  for (int i = 0; i < 3; ++i) u[i] = pos_[i] >= 0 ? state.u[pos_[i]] : 0.0;
  for (Eigen::Index i = 0; i < m; ++i) l[i] = lam_[static_cast<std::size_t>(i)] >= 0 ? state.u[lam_[static_cast<std::size_t>(i)]] : 0.0;
  Eigen::VectorXd R(3 + m);
  R.head<3>() = P_.transpose() * l;
  R.tail(m) = P_ * u;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 + m, 3 + m);
  K.topRightCorner(3, m) = P_.transpose();
  K.bottomLeftCorner(m, 3) = P_;
  out.add(d, R, K);
}

Eigen::Vector3d DirectionConstraintTerm::reaction(const Eigen::VectorXd& u) const {
  Eigen::VectorXd l(P_.rows());
  for (Eigen::Index i = 0; i < P_.rows(); ++i)
    l[i] = lam_[static_cast<std::size_t>(i)] >= 0 ? u[lam_[static_cast<std::size_t>(i)]] : 0.0;
  return P_.transpose() * l;
}

}  // namespace stentsim::solver::beams
