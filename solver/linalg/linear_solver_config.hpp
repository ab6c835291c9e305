#pragma once
// The one reader of a linear-solver name in a config file (scene, case,
// fibers stage): the names of linear_solver_names(), "did you mean" on a
// misspelling or an old spelling.
#include <string>

#include "common/config.hpp"
#include "solver/linalg/linear_solver.hpp"

namespace stentsim::solver {

inline LinearSolverType read_linear_solver(ConfigMap& m, const std::string& key, LinearSolverType def) {
  const std::string name = m.choice(key, linear_solver_names(), linear_solver_name(def));
  return parse_linear_solver(name, key);
}

}  // namespace stentsim::solver
