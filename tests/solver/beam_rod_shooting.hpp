#pragma once
// The rod shooting reference lives with the error study's references
// (workflows/study/references/rod_shooting.hpp, issue 11) so that the beam
// tests and `stentsim study error` measure against the same code; this
// header only makes its names visible where the beam tests look for them.
#include "workflows/study/references/rod_shooting.hpp"

namespace stentsim::solver::beams::testing {

using study::reference::rod_integrate;
using study::reference::rod_rhs;
using study::reference::rod_shoot;
using study::reference::rod_tip_under_force;
using study::reference::RodProblem;
using study::reference::RodState;

}  // namespace stentsim::solver::beams::testing
