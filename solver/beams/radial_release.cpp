#include "solver/beams/radial_release.hpp"

#include "common/error.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace stentsim::solver::beams {

RadialDisplacementTerm::RadialDisplacementTerm(std::string name, std::vector<Node> nodes, double value, LoadScale curve)
    : name_(std::move(name)), nodes_(std::move(nodes)), value_(value), curve_(std::move(curve)) {
  for (auto& n : nodes_) {
    const double l = n.radial.norm();
    if (!(l > 0.0) || !std::isfinite(l))
      throw InputError("radial displacement '" + name_ + "': a node has no radial direction (it lies on the axis)");
    n.radial /= l;
    if (n.multiplier < 0) throw std::logic_error("radial displacement '" + name_ + "': node without a multiplier DOF");
  }
  frozen_.assign(nodes_.size(), 0.0);
  last_lambda_.assign(nodes_.size(), 0.0);
}

void RadialDisplacementTerm::set_release(double time, LoadScale factor, double time_tolerance) {
  release_ = Release{time, std::move(factor), time_tolerance};
}

double RadialDisplacementTerm::multiplier(const Eigen::VectorXd& u, std::size_t k) const {
  return u[nodes_.at(k).multiplier];
}

void RadialDisplacementTerm::assemble(const SystemState& state, Assembler& out) {
  last_time_ = state.time;
  for (std::size_t k = 0; k < nodes_.size(); ++k) last_lambda_[k] = state.u[nodes_[k].multiplier];
  const bool after = release_ && state.time > release_->time + release_->tolerance;
  if (after && !released_)
    throw std::logic_error("radial displacement '" + name_ + "': a load step crossed the release time " +
                           std::to_string(release_->time) + " (it must be a stop)");
  if (state.rank != 0) return;  // added once
  const double target = value_ * (curve_ ? curve_(state.time) : 1.0);
  const double s = after ? release_->factor(state.time) : 0.0;
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    const Node& n = nodes_[k];
    const std::array<GlobalDof, 4> d{n.pos[0], n.pos[1], n.pos[2], n.multiplier};
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) u[i] = n.pos[i] >= 0 ? state.u[n.pos[i]] : 0.0;
    const double lambda = state.u[n.multiplier];
    Eigen::Vector4d R;
    Eigen::Matrix4d K = Eigen::Matrix4d::Zero();
    R.head<3>() = lambda * n.radial;
    K.block<3, 1>(0, 3) = n.radial;
    if (!after) {
      R[3] = n.radial.dot(u) - target;
      K.block<1, 3>(3, 0) = n.radial.transpose();
    } else {
      R[3] = lambda - frozen_[k] * s;
      K(3, 3) = 1.0;
    }
    out.add(d, R, K);
  }
}

void RadialDisplacementTerm::commit() {
  // The last assemble is at the converged state (Newton re-assembles after
  // its last update; BeamTerm::commit checks the same protocol).
  if (release_ && !released_ && std::abs(last_time_ - release_->time) <= release_->tolerance) {
    frozen_ = last_lambda_;
    released_ = true;
  }
}

void RadialDisplacementTerm::save_history(HistoryArchive& out, const std::string& prefix) const {
  out.put(prefix + "released", released_ ? 1.0 : 0.0);
  out.put(prefix + "frozen_multipliers", frozen_);
}

void RadialDisplacementTerm::load_history(const HistoryArchive& in, const std::string& prefix) {
  if (!release_) return;
  released_ = in.get_scalar(prefix + "released") != 0.0;
  frozen_ = in.get(prefix + "frozen_multipliers", static_cast<long long>(nodes_.size()));
}

}  // namespace stentsim::solver::beams
