#pragma once
// Semi-analytic reference for the two-layer HGO tube (issue 6, Case 1 artery
// alone): plane strain (lambda_z = 1), layers of the coupled compressible
// neo-Hooke matrix plus two exponential fiber families at +-phi in the
// (circumferential, axial) plane, follower pressure p on the deformed inner face.
//
// With r(R), lambda_r = r', lambda_t = r/R and I4 = cos^2(phi) lambda_t^2 + sin^2(phi)
// (symmetric families: no torsion, no shear), the nominal stresses are
//   P_r = 2c (lambda_r - J^(-2beta)/lambda_r),
//   P_t = 2c (lambda_t - J^(-2beta)/lambda_t) + 2 * 2 k1 e exp(k2 e^2) cos^2(phi) lambda_t,  e = I4 - 1,
// (fiber_family.hpp, coupled_neo_hooke.hpp). Radial equilibrium
// dP_r/dR + (P_r - P_t)/R = 0 with P_r(A) = -p lambda_t(A), P_r(B) = 0, and P_r
// continuous across the layer interface (lambda_r jumps there). Fibers add to
// P_t only, so the neo-Hooke shooting of workflows/study/references/tube_reference.hpp
// carries over; here it is solved by bisection on r(A) (robust to the
// exponential stiffening; 1e-12 relative).
#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <boost/numeric/odeint.hpp>

namespace stentsim::solver::test {

struct HgoLayer {
  double outer_radius;  // the layer spans from the previous layer's outer radius (or A) to this
  double c, beta;       // coupled neo-Hooke (c = E / (4 (1 + nu)), beta = nu / (1 - 2 nu))
  double k1, k2, phi_rad;
  int families = 2;     // coinciding families at phi = 0 count twice
};

class HgoTubeReference {
 public:
  HgoTubeReference(double inner_radius, std::vector<HgoLayer> layers) : a_(inner_radius), layers_(std::move(layers)) {}

  /// Deformed inner radius at follower pressure p (MPa): bisection on r(A) in
  /// [A, hi] on the sign of P_r(B) (a collapsed or non-finite shot counts as too large).
  double inner_radius(double p, double hi_factor = 4.0) const {
    double lo = a_, hi = hi_factor * a_;
    if (too_large(p, lo) || !too_large(p, hi)) throw std::runtime_error("HgoTubeReference: inner radius not bracketed");
    while (hi - lo > 1e-12 * a_) {
      const double mid = 0.5 * (lo + hi);
      (too_large(p, mid) ? hi : lo) = mid;
    }
    return 0.5 * (lo + hi);
  }

  /// Fiber stretch sqrt(I4) of the innermost layer at the inner face, for inner radius r_inner.
  double inner_fiber_stretch(double r_inner) const {
    const auto& L = layers_.front();
    const double lt = r_inner / a_;
    return std::sqrt(std::cos(L.phi_rad) * std::cos(L.phi_rad) * lt * lt + std::sin(L.phi_rad) * std::sin(L.phi_rad));
  }

 private:
  static double jpow(const HgoLayer& L, double lr, double lt) { return std::exp(-2 * L.beta * std::log(lr * lt)); }
  static double p_r(const HgoLayer& L, double lr, double lt) { return 2 * L.c * (lr - jpow(L, lr, lt) / lr); }
  static double dpr_dlr(const HgoLayer& L, double lr, double lt) {
    return 2 * L.c * (1 + (1 + 2 * L.beta) * jpow(L, lr, lt) / (lr * lr));
  }
  static double p_t(const HgoLayer& L, double lr, double lt) {
    const double c2 = std::cos(L.phi_rad) * std::cos(L.phi_rad), s2 = 1 - c2;
    const double e = c2 * lt * lt + s2 - 1;
    const double fiber = L.families * 2 * L.k1 * e * std::exp(std::min(L.k2 * e * e, 700.0)) * c2 * lt;
    return 2 * L.c * (lt - jpow(L, lr, lt) / lt) + fiber;
  }
  // lambda_r with P_r(lambda_r, lt) = target (P_r increases monotonically in lambda_r).
  static double lambda_r_for(const HgoLayer& L, double target, double lt, double guess) {
    double lr = guess;
    for (int it = 0; it < 200; ++it) {
      const double step = (p_r(L, lr, lt) - target) / dpr_dlr(L, lr, lt);
      lr = std::max(lr - step, 0.5 * lr);
      if (std::abs(step) < 1e-15 * lr) break;
    }
    return lr;
  }

  // True when inner radius r_inner overshoots the equilibrium at p (P_r(B) > 0).
  bool too_large(double p, double r_inner) const {
    double r = 0, pr = 0;
    return !shoot(p, r_inner, layers_.back().outer_radius, r, pr) || pr > 0;
  }

 public:
  /// Deformed radius at reference radius R (A <= R <= B) for inner radius r_inner under p.
  double radius_at(double p, double r_inner, double R) const {
    double r = 0, pr = 0;
    if (!shoot(p, r_inner, R, r, pr)) throw std::runtime_error("HgoTubeReference: shot failed");
    return r;
  }

 private:
  // Integrates (r, lambda_r) from A to R_end; false if lambda_r collapsed or went non-finite.
  bool shoot(double p, double r_inner, double R_end, double& r_end, double& pr_end) const {
    using State = std::array<double, 2>;  // r, lambda_r
    double R0 = a_;
    State y{r_inner, 1.0};
    double pr = -p * r_inner / a_;  // P_r at the inner face
    for (const auto& L : layers_) {
      if (R0 >= R_end) break;
      const double R1 = std::min(L.outer_radius, R_end);
      y[1] = lambda_r_for(L, pr, y[0] / R0, y[1]);
      if (!std::isfinite(y[1]) || y[1] <= 0) return false;
      auto rhs = [&L](const State& s, State& d, double R) {
        const double lr = s[1], lt = s[0] / R, jp = jpow(L, lr, lt);
        const double dprdlt = 4 * L.c * L.beta * jp / (lr * lt);
        d[0] = lr;
        d[1] = -((p_r(L, lr, lt) - p_t(L, lr, lt)) / R + dprdlt * (lr - lt) / R) / dpr_dlr(L, lr, lt);
      };
      namespace ode = boost::numeric::odeint;
      try {
        auto stepper = ode::make_controlled(1e-13, 1e-12, ode::runge_kutta_dopri5<State>());
        ode::integrate_adaptive(stepper, rhs, y, R0, R1, (R1 - R0) / 64);
      } catch (const std::exception&) {
        return false;
      }
      if (!std::isfinite(y[0]) || !std::isfinite(y[1]) || y[1] <= 0) return false;
      pr = p_r(L, y[1], y[0] / R1);
      R0 = R1;
    }
    r_end = y[0];
    pr_end = pr;
    return true;
  }

  double a_;
  std::vector<HgoLayer> layers_;
};

}  // namespace stentsim::solver::test
