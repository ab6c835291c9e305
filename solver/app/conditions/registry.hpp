#pragma once
// The condition kinds, one factory per file (solid_conditions.cpp, beam_conditions.cpp);
// registry.cpp lists them.
#include "solver/io/scene_kinds.hpp"

namespace stentsim::solver {

ConditionKind pressure_condition();
ConditionKind springs_condition();
ConditionKind dirichlet_condition();
ConditionKind clamp_condition();
ConditionKind point_force_condition();
ConditionKind point_moment_condition();
ConditionKind direction_condition();
ConditionKind radial_displacement_condition();
ConditionKind fix_cylindrical_condition();
ConditionKind release_condition();

}  // namespace stentsim::solver
