#pragma once
// A term could not evaluate a trial state (inverted element, overflow, NaN).
// The nonlinear solver treats it as a failed iteration (backtrack, cut the
// step) and reports the message only when the minimum step fails (DESIGN.md §7).
#include "common/error.hpp"

namespace stentsim::solver {

class ElementFailure : public ComputeError {
 public:
  using ComputeError::ComputeError;
};

}  // namespace stentsim::solver
