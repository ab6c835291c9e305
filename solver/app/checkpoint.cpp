#include "solver/app/checkpoint.hpp"

#include <span>

namespace stentsim::solver {

void SolverCheckpoint::put(HistoryArchive& out) const {
  out.put("solver/u", std::span<const double>(u.data(), static_cast<std::size_t>(u.size())));
  out.put("solver/time", time);
  out.put("solver/next_dt", next_dt);
  out.put("solver/newton_iterations", static_cast<double>(counters.newton_iterations));
  out.put("solver/linear_iterations", static_cast<double>(counters.linear_iterations));
  out.put("solver/step_cuts", static_cast<double>(counters.step_cuts));
  out.put("solver/steps", static_cast<double>(counters.steps));
  out.put("solver/predicted_steps", static_cast<double>(counters.predicted_steps));
  out.put("solver/last_increment", std::span<const double>(last_increment.data(), static_cast<std::size_t>(last_increment.size())));
  out.put("solver/last_dt", last_dt);
}

SolverCheckpoint SolverCheckpoint::get(const HistoryArchive& in, long long dofs) {
  SolverCheckpoint c;
  const auto& u = in.get("solver/u", dofs);
  c.u = Eigen::Map<const Eigen::VectorXd>(u.data(), static_cast<Eigen::Index>(u.size()));
  c.time = in.get_scalar("solver/time");
  c.next_dt = in.get_scalar("solver/next_dt");
  c.counters.newton_iterations = static_cast<long>(in.get_scalar("solver/newton_iterations"));
  c.counters.linear_iterations = static_cast<long>(in.get_scalar("solver/linear_iterations"));
  c.counters.step_cuts = static_cast<long>(in.get_scalar("solver/step_cuts"));
  c.counters.steps = static_cast<int>(in.get_scalar("solver/steps"));
  // Checkpoints written without a predictor state resume without a guess for their first step.
  if (in.has("solver/predicted_steps")) c.counters.predicted_steps = static_cast<int>(in.get_scalar("solver/predicted_steps"));
  if (in.has("solver/last_increment") && !in.get("solver/last_increment").empty()) {
    const auto& inc = in.get("solver/last_increment", dofs);
    c.last_increment = Eigen::Map<const Eigen::VectorXd>(inc.data(), static_cast<Eigen::Index>(inc.size()));
  }
  if (in.has("solver/last_dt")) c.last_dt = in.get_scalar("solver/last_dt");
  return c;
}

}  // namespace stentsim::solver
