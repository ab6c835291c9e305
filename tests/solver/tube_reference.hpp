#pragma once
// Semi-analytic reference for the solver's tube tests: forwards to the error
// study's reference (workflows/study/references/tube_reference.hpp, issue 11),
// the plane-strain coupled neo-Hooke radial BVP solved by adaptive Runge-Kutta
// shooting and Newton to far below 1e-10 relative, so that the solver test and
// the convergence study measure against the same numbers.
#include "workflows/study/references/tube_reference.hpp"

namespace stentsim::solver::test {

struct TubeReference {
  double c, beta, ri, ro;

  /// Deformed inner radius at follower pressure p.
  double inner_radius(double p) const { return study::reference::PlaneStrainTube(c, beta, ri, ro).inner_radius(p); }
};

}  // namespace stentsim::solver::test
