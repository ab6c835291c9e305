#pragma once
// Generalized-Maxwell viscous branch (paper App. B; Holzapfel & Gasser 2001):
//   dQ/dt + Q / tau = beta dS_inf/dt,   S = S_inf + Q,
// integrated exactly for S_inf linear over the step (DESIGN.md §8), with the
// actual step size of the adaptive stepper:
//   Q_{n+1} = e^(-x) Q_n + beta (1 - e^(-x)) / x (S_inf,{n+1} - S_inf,n),  x = dt / tau.
// Its tangent adds beta (1 - e^(-x)) / x dS_inf/dE.
#include <cmath>

#include "solver/fem/tensor.hpp"

namespace stentsim::solver {

/// History of one quadrature point: Q and S_inf at the last committed step.
struct ViscousHistory {
  Vec6 q = Vec6::Zero();
  Vec6 s_inf = Vec6::Zero();
};

struct ViscousBranch {
  double tau = 0.5;   // relaxation time, s
  double beta = 0.3;  // ratio of viscous to hyperelastic branch

  /// beta (1 - e^(-x)) / x, with its limit beta at x = 0.
  double gain(double dt) const {
    const double x = dt / tau;
    return x < 1e-12 ? beta * (1.0 - 0.5 * x) : beta * (-std::expm1(-x)) / x;
  }
  double decay(double dt) const { return std::exp(-dt / tau); }

  /// Q at the end of the step from the committed history and the new S_inf.
  Vec6 update(const ViscousHistory& committed, const Vec6& s_inf_new, double dt) const {
    return decay(dt) * committed.q + gain(dt) * (s_inf_new - committed.s_inf);
  }
};

}  // namespace stentsim::solver
