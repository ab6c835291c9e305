#pragma once
// Prescribed radial displacement of beam nodes that can later be released
// into the force it needed (issue 9, the stent ring: crowns pushed out, then
// let go).
//
// Until the release time t_r the condition is a Lagrange multiplier per node:
//   (r − X)·e_r = v·c(t),  residual at the position DOFs  + λ e_r,
// where e_r is the node's reference radial direction about the axis (fixed in
// space, as a Dirichlet condition in a nodal frame) and λ is the radial force
// the body exerts on the support (the reaction is −λ e_r). At the converged
// step ending at t_r the multipliers are frozen (λ_r, committed history); for
// t > t_r the condition is a dead point force of the same size scaled by the
// release curve s(t) (s(t_r) = 1):
//   residual at the position DOFs  + λ e_r,   multiplier row  λ − λ_r s(t),
// so the crowns first carry exactly their last reaction and are then unloaded
// as s goes to 0. Both phases are linear in the DOFs (tangent exact).
// MPI: added on rank 0 only; every rank records the multipliers from its u.
#include "solver/beams/beam_loads.hpp"
#include "solver/terms/term.hpp"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace stentsim::solver::beams {

class RadialDisplacementTerm : public Term {
 public:
  struct Node {
    std::array<GlobalDof, 3> pos{-1, -1, -1};
    Eigen::Vector3d radial = Eigen::Vector3d::UnitX();  // unit, reference e_r
    GlobalDof multiplier = -1;
  };
  /// Prescribes (r − X)·e_r = value·curve(t) at every node.
  RadialDisplacementTerm(std::string name, std::vector<Node> nodes, double value, LoadScale curve);

  /// Releases the condition at `time` (a step must end there) into point
  /// forces equal to the reactions, scaled by `factor` (factor(time) = 1).
  void set_release(double time, LoadScale factor, double time_tolerance);
  bool released() const { return released_; }
  /// Radial force λ of node k that the body exerts on the support at u (N).
  double multiplier(const Eigen::VectorXd& u, std::size_t k) const;
  const std::vector<Node>& nodes() const { return nodes_; }

  std::string name() const override { return name_; }
  void assemble(const SystemState& state, Assembler& out) override;
  void commit() override;
  bool has_history() const override { return release_.has_value(); }
  /// "<prefix>released" (0/1) and "<prefix>frozen_multipliers" (λ_r per node).
  void save_history(HistoryArchive& out, const std::string& prefix) const override;
  void load_history(const HistoryArchive& in, const std::string& prefix) override;

 private:
  struct Release {
    double time;
    LoadScale factor;
    double tolerance;
  };
  std::string name_;
  std::vector<Node> nodes_;
  double value_;
  LoadScale curve_;
  std::optional<Release> release_;
  bool released_ = false;
  std::vector<double> frozen_;        // λ_r per node
  std::vector<double> last_lambda_;   // multipliers at the last assemble
  double last_time_ = 0.0;
};

}  // namespace stentsim::solver::beams
