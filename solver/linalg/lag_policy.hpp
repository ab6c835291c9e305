#pragma once
// When a Krylov solver sets its preconditioner up again
// (LinearSolverSettings::lag_preconditioner). A set-up costs S seconds (AMG's
// coarse operators RAP and smoothers: on the patient example 1–3 s, about as
// much as the GMRES solve it serves); a preconditioner of an earlier Newton
// iterate's matrix costs extra GMRES iterations instead. A lagged solve that
// reached the relative residual r in n iterations would have needed
// log r / log rho with a fresh preconditioner, rho being the per-iteration
// reduction of the latest fresh solve that ended in the same decade of relative
// residual (GMRES slows as it goes deeper: on the patient example 24
// iterations to 1e-2 but 69 to 3e-4, so one rate for every depth would charge
// a deep lagged solve for iterations a fresh one needs too). The difference, at
// the lagged solve's time per iteration, is that solve's extra cost. Once the
// extra cost summed since the last set-up reaches S, the next solve sets up
// afresh: the break-even rule of the ski-rental problem (Karlin et al.,
// Algorithmica 3, 1988), which never pays more than twice what the best choice
// in hindsight would have. Lagging changes GMRES's preconditioner only, never
// the operator: every solve still reaches its tolerance on the current matrix
// (a lagged solve that does not within iteration_cap is repeated with a fresh
// set-up).
#include <algorithm>
#include <array>
#include <cmath>

namespace stentsim::solver {

class LagPolicy {
 public:
  /// True when the next solve may keep the last preconditioner as it is.
  bool may_lag() const { return lagging_ && extra_ < setup_; }

  /// A preconditioner was set up (in `setup_seconds`); its first solve took
  /// `iterations` (in `seconds`) to reach the relative residual `achieved`.
  void built(double setup_seconds, int iterations, double achieved, double seconds) {
    setup_ = setup_seconds;
    extra_ = 0.0;
    // No rate from a solve that took no iteration (a zero right-hand side) or did not reduce:
    // nothing to judge a lagged solve by, so the next one sets up afresh.
    lagging_ = iterations > 0 && achieved > 0.0 && achieved < 1.0;
    if (!lagging_) return;
    iteration_seconds_ = seconds / iterations;
    log_rate_[decade(achieved)] = std::log(achieved) / iterations;
  }

  /// A solve with the lagged preconditioner took `iterations` (in `seconds`) to reach `achieved`.
  void lagged(int iterations, double achieved, double seconds) {
    if (iterations <= 0 || !lagging_) return;
    const double r = std::clamp(achieved, 1e-300, 1.0);
    const double fresh = std::log(r) / fresh_log_rate(r);
    extra_ += std::max(0.0, iterations - fresh) * seconds / iterations;
  }

  /// The iterations a lagged solve to `tolerance` may take before it is given up
  /// for a fresh set-up: a fresh preconditioner's count plus what the rest of
  /// the set-up's cost buys (never more than `max_iterations`).
  int iteration_cap(double tolerance, int max_iterations) const {
    if (!lagging_ || iteration_seconds_ <= 0.0) return max_iterations;
    const double r = std::clamp(tolerance, 1e-300, 1.0);
    const double cap = std::ceil(std::log(r) / fresh_log_rate(r) + std::max(0.0, setup_ - extra_) / iteration_seconds_) + 1.0;
    return static_cast<int>(std::min(cap, static_cast<double>(max_iterations)));
  }

  double setup_seconds() const { return setup_; }
  double extra_seconds() const { return extra_; }

 private:
  static constexpr int decades = 17;
  static int decade(double r) { return std::clamp(static_cast<int>(std::floor(-std::log10(r))), 0, decades - 1); }
  // The rate of the nearest decade a fresh solve has ended in (at least one has: lagging_).
  double fresh_log_rate(double r) const {
    const int d = decade(r);
    for (int k = 0; k < decades; ++k) {
      if (d - k >= 0 && log_rate_[d - k] < 0.0) return log_rate_[d - k];
      if (d + k < decades && log_rate_[d + k] < 0.0) return log_rate_[d + k];
    }
    return -1.0;  // unreachable while lagging_
  }

  bool lagging_ = false;            // a fresh solve gave a rate
  double setup_ = 0.0;              // the last set-up's cost
  double extra_ = 0.0;              // the lagged solves' extra GMRES time since
  double iteration_seconds_ = 0.0;  // the last fresh solve's time per GMRES iteration
  std::array<double, decades> log_rate_{};  // log rho of the latest fresh solve per decade of r (0: none)
};

}  // namespace stentsim::solver
