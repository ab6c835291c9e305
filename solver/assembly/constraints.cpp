#include "solver/assembly/constraints.hpp"

#include <stdexcept>

namespace stentsim::solver {

void Constraints::resize(GlobalDof n) {
  fixed_.assign(static_cast<std::size_t>(n), 0);
  frame_start_.assign(static_cast<std::size_t>(n), 0);
  values_.clear();
  frames_.clear();
}

void Constraints::set_frame(GlobalDof first, const Mat3& q) {
  if (first < 0 || first + 2 >= size()) throw std::out_of_range("Constraints::set_frame: DOF out of range");
  if ((q.transpose() * q - Mat3::Identity()).norm() > 1e-10) throw std::invalid_argument("Constraints::set_frame: frame not orthonormal");
  frames_[first] = q;
  frame_start_[static_cast<std::size_t>(first)] = 1;
}

void Constraints::fix(GlobalDof dof, std::function<double(double)> value) {
  if (dof < 0 || dof >= size()) throw std::out_of_range("Constraints::fix: DOF out of range");
  fixed_[static_cast<std::size_t>(dof)] = 1;
  values_[dof] = std::move(value);
}

const Mat3* Constraints::frame(GlobalDof first) const {
  auto it = frames_.find(first);
  return it == frames_.end() ? nullptr : &it->second;
}

std::size_t Constraints::num_fixed() const {
  std::size_t n = 0;
  for (char f : fixed_) n += f ? 1 : 0;
  return n;
}

Eigen::VectorXd Constraints::increments(const Eigen::VectorXd& u, double t) const {
  Eigen::VectorXd local = u;
  to_local(local);
  Eigen::VectorXd du = Eigen::VectorXd::Zero(u.size());
  for (const auto& [dof, value] : values_) du(dof) = value(t) - local(dof);
  return du;
}

void Constraints::to_local(Eigen::VectorXd& v) const {
  for (const auto& [first, q] : frames_) v.segment<3>(first) = q.transpose() * v.segment<3>(first);
}

void Constraints::to_global(Eigen::VectorXd& v) const {
  for (const auto& [first, q] : frames_) v.segment<3>(first) = q * v.segment<3>(first);
}

}  // namespace stentsim::solver
