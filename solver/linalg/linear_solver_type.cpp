#include <fmt/format.h>

#include <algorithm>

#include "common/config.hpp"
#include "common/error.hpp"
#include "solver/linalg/linear_solver.hpp"

namespace stentsim::solver {

const std::vector<std::string>& linear_solver_names() {
  static const std::vector<std::string> names{"direct", "gmres_ilu", "gmres_amg", "eigen_lu", "gmres_amg_block", "gmres_lu"};
  return names;
}

const std::string& linear_solver_name(LinearSolverType type) { return linear_solver_names()[static_cast<std::size_t>(type)]; }

bool one_rank_only(LinearSolverType type) {
  return type == LinearSolverType::gmres_amg_block || type == LinearSolverType::gmres_lu || type == LinearSolverType::eigen_lu;
}

LinearSolverType parse_linear_solver(const std::string& name, const std::string& where) {
  const auto& names = linear_solver_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return static_cast<LinearSolverType>(it - names.begin());
  const std::string near = closest_name(names, name);
  throw InputError(fmt::format("{}: '{}' is not one of: {}{}", where, name, fmt::join(names, ", "),
                               near.empty() ? std::string() : fmt::format(" (did you mean '{}'?)", near)));
}

}  // namespace stentsim::solver
