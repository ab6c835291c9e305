#pragma once
// Reference solution for the tube-inflation verification (DESIGN.md §6, §8;
// issue 11): a thick-walled tube of the coupled compressible neo-Hooke of
// DESIGN.md §5, Psi = c (I1 - 3) + (c/beta) (J^(-2beta) - 1), in plane strain
// (lambda_z = 1) under a follower pressure p on the deformed inner face.
//
// With r(R) the deformed radius, lambda_r = r', lambda_t = r/R, J = lambda_r lambda_t,
// the nominal stresses are P_k = dPsi/dlambda_k = 2c (lambda_k - J^(-2beta)/lambda_k)
// and radial equilibrium is the boundary-value problem
//   dP_r/dR + (P_r - P_t)/R = 0,  P_r(A) = -p r(A)/A,  P_r(B) = 0.
// It is solved by shooting on r(A): an adaptive Runge-Kutta (Dormand-Prince
// 5(4), Boost.Odeint) integrates (r, lambda_r) from A to B and Newton drives
// P_r(B) to zero until r(A) changes by less than 1e-10 relative (typically
// far less). Never the incompressible closed form: at nu = 0.45 it is 4-5 %
// off (DESIGN.md §8).
//
// Header-only so that both the solver's tube test and the error study use the
// same code without a link dependency.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include <boost/numeric/odeint.hpp>

namespace stentsim::study::reference {

class PlaneStrainTube {
 public:
  /// c = E / (4 (1 + nu)), beta = nu / (1 - 2 nu) (coupled_neo_hooke.hpp); A < B radii in mm.
  PlaneStrainTube(double c, double beta, double inner, double outer) : c_(c), beta_(beta), a_(inner), b_(outer) {
    if (!(c > 0) || !(beta >= 0) || !(inner > 0) || !(outer > inner))
      throw std::invalid_argument("PlaneStrainTube: need c > 0, beta >= 0, 0 < inner < outer");
  }
  static PlaneStrainTube from_young(double E, double nu, double inner, double outer) {
    return PlaneStrainTube(E / (4 * (1 + nu)), nu / (1 - 2 * nu), inner, outer);
  }

  /// Deformed inner radius at follower pressure p (MPa). Throws std::runtime_error
  /// when no equilibrium exists (p at or above the asymptotic pressure).
  double inner_radius(double p) const {
    if (p == 0) return a_;
    // Continuation in p from the unloaded tube: near incompressibility a guess
    // far from the solution sends lambda_r through zero inside the wall, so each
    // Newton solve starts from the previous pressure's radius (extrapolated),
    // and a failed solve halves the pressure increment.
    double q = 0, r = a_, drdq = lame_inner_displacement(1.0);
    double dq = p / 4;
    while (q < p) {
      dq = std::min(dq, p - q);
      const auto solved = newton(q + dq, r + drdq * dq);
      if (!solved) {
        dq /= 2;
        if (dq < 1e-8 * p)
          throw std::runtime_error("tube reference: no equilibrium beyond p = " + std::to_string(q) +
                                   " on the way to p = " + std::to_string(p) + " (asymptotic pressure " +
                                   std::to_string(asymptotic_pressure()) + ")");
        continue;
      }
      drdq = (*solved - r) / dq;
      r = *solved;
      q += dq;
      dq *= 1.5;
    }
    return r;
  }

  /// Newton on r(A) from r0 with a central-difference slope (the residual is
  /// smooth in r(A); the slope only sets the rate). Converged when r(A) moves
  /// by less than 1e-12 relative, 100x tighter than the required 1e-10; a
  /// non-finite residual backtracks the step, and empty means no convergence.
  std::optional<double> newton(double p, double r0) const {
    double r = r0;
    double f = outer_residual(p, r);
    if (!std::isfinite(f)) return std::nullopt;
    for (int it = 0; it < 50; ++it) {
      const double h = 1e-7 * r;
      const double df = (outer_residual(p, r + h) - outer_residual(p, r - h)) / (2 * h);
      if (!std::isfinite(df) || df <= 0) return std::nullopt;
      double step = std::clamp(-f / df, -0.2 * r, 0.2 * r);
      double trial = r + step, ft = outer_residual(p, trial);
      for (int back = 0; back < 30 && !std::isfinite(ft); ++back) {
        step /= 2;
        trial = r + step;
        ft = outer_residual(p, trial);
      }
      if (!std::isfinite(ft)) return std::nullopt;
      r = trial;
      f = ft;
      if (std::abs(step) < 1e-12 * r) return r;
      if (r > 1e4 * a_) return std::nullopt;
    }
    return std::nullopt;
  }

  /// Pressure that holds the inner radius at r_inner: bisection on p inside
  /// [lo, hi], which must bracket it (residual > 0 at lo, < 0 at hi); a
  /// non-finite residual counts as "p too large" (lambda_r collapsed).
  double pressure_at(double r_inner, double lo, double hi) const {
    auto above = [&](double p) {
      const double g = outer_residual(p, r_inner);
      return !std::isfinite(g) || g < 0;
    };
    if (above(lo)) throw std::runtime_error("tube reference: pressure not bracketed from below");
    for (int k = 0; k < 60 && !above(hi); ++k) std::tie(lo, hi) = std::pair{hi, 2 * hi};  // grow the bracket upwards
    if (!above(hi)) throw std::runtime_error("tube reference: pressure not bracketed from above");
    for (int it = 0; it < 200 && hi - lo > 1e-13 * hi; ++it) {
      const double p = 0.5 * (lo + hi);
      (above(p) ? hi : lo) = p;
    }
    return 0.5 * (lo + hi);
  }

  /// Limit of p as r(A) grows without bound: no equilibrium exists above it
  /// (the tube "balloons"; incompressible plane strain gives mu ln(B/A)).
  /// Continuation in r(A) = A q^k with q = 1.25, each pressure bracketed
  /// around the previous one, until p changes by less than 1e-5 relative.
  double asymptotic_pressure() const {
    double r = a_ * 1.25;
    double p = pressure_at(r, 0.0, 1e-3 * c_);
    for (int k = 0; k < 80; ++k) {
      r *= 1.25;
      const double next = pressure_at(r, 0.8 * p, 1.5 * p);
      if (std::abs(next - p) < 1e-5 * next) return next;
      p = next;
    }
    throw std::runtime_error("tube reference: asymptotic pressure did not level off");
  }

  /// Small-strain plane-strain Lame displacement of the inner face, with
  /// lambda = 2 mu beta... expressed in (c, beta): mu = 2c, lambda = 4 c beta.
  double lame_inner_displacement(double p) const {
    const double mu = 2 * c_, lambda = 4 * c_ * beta_;
    const double a2 = a_ * a_, b2 = b_ * b_;
    const double B = p * a2 * b2 / (2 * mu * (b2 - a2));
    const double Acoef = p * a2 / (2 * (lambda + mu) * (b2 - a2));
    return Acoef * a_ + B / a_;
  }

  /// (r, lambda_r) at B when the inner radius is r_inner under pressure p.
  std::array<double, 2> shoot(double p, double r_inner) const {
    using State = std::array<double, 2>;  // r, lambda_r
    State y{r_inner, inner_lambda_r(p, r_inner / a_)};
    auto rhs = [this](const State& s, State& d, double R) {
      d[0] = s[1];
      d[1] = dlambda_r(R, s[0], s[1]);
    };
    namespace ode = boost::numeric::odeint;
    auto stepper = ode::make_controlled(1e-14, 1e-13, ode::runge_kutta_dopri5<State>());
    ode::integrate_adaptive(stepper, rhs, y, a_, b_, (b_ - a_) / 64);
    return y;
  }

  /// Radial nominal stress P_r at B when the inner radius is r_inner under pressure p.
  double outer_traction(double p, double r_inner) const {
    const auto y = shoot(p, r_inner);
    return p_r(y[1], y[0] / b_);
  }

  /// The shooting residual: P_r(B) = (2c/lambda_r) (lambda_r^2 - J^(-2beta)) vanishes
  /// exactly when ln lambda_r + beta ln J = 0 at B. This form is nearly linear in
  /// r(A) even at nu = 0.4999, where P_r(B) itself varies like J^(-2beta) and
  /// Newton on it crawls; it has the sign of P_r(B).
  double outer_residual(double p, double r_inner) const {
    const auto y = shoot(p, r_inner);
    return std::log(y[1]) + beta_ * std::log(y[1] * y[0] / b_);
  }

  double c() const { return c_; }
  double beta() const { return beta_; }

 private:
  // J^(-2beta) as exp(-2beta ln J): no overflow near incompressibility.
  double jpow(double lr, double lt) const { return std::exp(-2 * beta_ * std::log(lr * lt)); }
  double p_r(double lr, double lt) const { return 2 * c_ * (lr - jpow(lr, lt) / lr); }
  double p_t(double lr, double lt) const { return 2 * c_ * (lt - jpow(lr, lt) / lt); }

  // d lambda_r / dR from dP_r/dR = dP_r/dlr lr' + dP_r/dlt (lr - lt)/R = -(P_r - P_t)/R.
  double dlambda_r(double R, double r, double lr) const {
    const double lt = r / R, jp = jpow(lr, lt);
    const double dpr_dlr = 2 * c_ * (1 + (1 + 2 * beta_) * jp / (lr * lr));
    const double dpr_dlt = 4 * c_ * beta_ * jp / (lr * lt);
    return -((p_r(lr, lt) - p_t(lr, lt)) / R + dpr_dlt * (lr - lt) / R) / dpr_dlr;
  }

  // lambda_r at A from P_r = -p lambda_t (P_r increases monotonically in lambda_r).
  double inner_lambda_r(double p, double lt) const {
    double lr = 1.0;
    for (int it = 0; it < 200; ++it) {
      const double f = p_r(lr, lt) + p * lt;
      const double df = 2 * c_ * (1 + (1 + 2 * beta_) * jpow(lr, lt) / (lr * lr));
      const double step = f / df;
      lr = std::max(lr - step, 0.5 * lr);
      if (std::abs(step) < 1e-15 * lr) break;
    }
    return lr;
  }

  double c_, beta_, a_, b_;
};

}  // namespace stentsim::study::reference
