#pragma once
// Semi-analytic reference for a thick-walled tube of coupled compressible
// neo-Hooke (DESIGN.md §5, §8) in plane strain under follower pressure p on
// the inner surface: the radial boundary-value problem
//   dP_r/dR + (P_r - P_t)/R = 0,  P_r(R_i) = -p lambda_t(R_i),  P_r(R_o) = 0,
// with principal stretches lambda_r = r', lambda_t = r/R, lambda_z = 1 and
// P_k = dPsi/dlambda_k = 2c (lambda_k - J^(-2beta)/lambda_k), J = lambda_r lambda_t.
// Shooting on r(R_i), RK4 in R, bisection to 1e-13: accurate far below 1e-10.
#include <cmath>
#include <stdexcept>

namespace stentsim::solver::test {

struct TubeReference {
  double c, beta, ri, ro;

  double jpow(double lr, double lt) const { return std::exp(-2 * beta * std::log(lr * lt)); }
  double p_r(double lr, double lt) const { return 2 * c * (lr - jpow(lr, lt) / lr); }
  double p_t(double lr, double lt) const { return 2 * c * (lt - jpow(lr, lt) / lt); }

  // d lambda_r / dR from equilibrium.
  double dlr(double radius, double r, double lr) const {
    const double lt = r / radius, jp = jpow(lr, lt);
    const double dpr_dlr = 2 * c * (1 + (1 + 2 * beta) * jp / (lr * lr));
    const double dpr_dlt = 4 * c * beta * jp / (lr * lt);
    return -((p_r(lr, lt) - p_t(lr, lt)) / radius + dpr_dlt * (lr - lt) / radius) / dpr_dlr;
  }

  // lambda_r at the inner surface from P_r = -p lambda_t (Newton, P_r increasing in lambda_r).
  double inner_lr(double p, double lt) const {
    double lr = 1.0;
    for (int it = 0; it < 100; ++it) {
      const double f = p_r(lr, lt) + p * lt;
      const double df = 2 * c * (1 + (1 + 2 * beta) * jpow(lr, lt) / (lr * lr));
      const double step = f / df;
      lr = std::max(lr - step, 0.5 * lr);
      if (std::abs(step) < 1e-15) break;
    }
    return lr;
  }

  // P_r at R_o when the inner radius is r_inner.
  double outer_traction(double p, double r_inner, int steps = 4000) const {
    double radius = ri, r = r_inner, lr = inner_lr(p, r_inner / ri);
    const double h = (ro - ri) / steps;
    for (int s = 0; s < steps; ++s) {
      auto f = [&](double rr, double y0, double y1) { return std::pair{y1, dlr(rr, y0, y1)}; };
      auto [k1a, k1b] = f(radius, r, lr);
      auto [k2a, k2b] = f(radius + h / 2, r + h / 2 * k1a, lr + h / 2 * k1b);
      auto [k3a, k3b] = f(radius + h / 2, r + h / 2 * k2a, lr + h / 2 * k2b);
      auto [k4a, k4b] = f(radius + h, r + h * k3a, lr + h * k3b);
      r += h / 6 * (k1a + 2 * k2a + 2 * k3a + k4a);
      lr += h / 6 * (k1b + 2 * k2b + 2 * k3b + k4b);
      radius += h;
    }
    return p_r(lr, r / ro);
  }

  /// Deformed inner radius at pressure p.
  double inner_radius(double p, int steps = 4000) const {
    double lo = ri, hi = ri * 1.01;
    while (outer_traction(p, hi, steps) < 0) {
      lo = hi;
      hi = ri + 2 * (hi - ri);
      if (hi > 10 * ri) throw std::runtime_error("tube reference: no bracket");
    }
    for (int it = 0; it < 200 && hi - lo > 1e-14 * ri; ++it) {
      const double mid = 0.5 * (lo + hi);
      (outer_traction(p, mid, steps) < 0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
};

}  // namespace stentsim::solver::test
