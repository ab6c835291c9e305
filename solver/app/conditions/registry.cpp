#include "solver/app/conditions/registry.hpp"

namespace stentsim::solver {

const std::vector<ConditionKind>& condition_kinds() {
  static const std::vector<ConditionKind> kinds{
      pressure_condition(),     springs_condition(),       dirichlet_condition(),
      clamp_condition(),        point_force_condition(),   point_moment_condition(),
      direction_condition(),    radial_displacement_condition(), fix_cylindrical_condition(),
      release_condition()};
  return kinds;
}

}  // namespace stentsim::solver
