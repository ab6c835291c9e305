#pragma once
// The solver's own part of checkpoint.bin (HistoryArchive keys "solver/…"):
// the state vector, the time reached, the step size to try next, the last
// step's increment and size (the predictor's start) and the run's counters. Terms (Model::save_history), the results writer and the run
// observers add their parts under their own prefixes.
#include <Eigen/Core>

#include "solver/terms/history_archive.hpp"

namespace stentsim::solver {

struct RunCounters {
  long newton_iterations = 0, linear_iterations = 0, step_cuts = 0;
  int steps = 0;
  int predicted_steps = 0;  // steps whose converged attempt started from the predictor's guess
};

struct SolverCheckpoint {
  Eigen::VectorXd u;
  double time = 0.0, next_dt = 0.0;
  Eigen::VectorXd last_increment;  // empty: no predictor for the first step after the restart
  double last_dt = 0.0;
  RunCounters counters;

  void put(HistoryArchive& out) const;
  /// Reads it back; InputError (naming the checkpoint) when a field is missing or u has another size.
  static SolverCheckpoint get(const HistoryArchive& in, long long dofs);
};

}  // namespace stentsim::solver
