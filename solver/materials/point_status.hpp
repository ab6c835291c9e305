#pragma once
// Outcome of a material-point evaluation. Failure is reported, never turned
// into Inf/NaN (DESIGN.md §7): the element names itself and the nonlinear
// solver treats it as a failed trial state.
namespace stentsim::solver {

struct PointStatus {
  bool ok = true;
  const char* why = "";  // static text, e.g. "J <= 0"
  static PointStatus good() { return {}; }
  static PointStatus fail(const char* reason) { return {false, reason}; }
};

}  // namespace stentsim::solver
