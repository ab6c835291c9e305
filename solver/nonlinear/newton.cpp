#include "solver/nonlinear/newton.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/terms/element_failure.hpp"

namespace stentsim::solver {
namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Norm of the reactions at fixed DOFs: the force scale under pure displacement loading.
double reaction_norm(const Constraints& c, const Eigen::VectorXd& r) {
  double s = 0.0;
  for (GlobalDof d = 0; d < r.size(); ++d)
    if (c.fixed(d)) s += r(d) * r(d);
  return std::sqrt(s);
}
}  // namespace

NewtonResult newton_step(Model& model, GlobalSystem& system, LinearSolver& linear, Eigen::VectorXd& u, double time,
                         double dt, const NewtonSettings& settings) {
  NewtonResult res;
  const Eigen::VectorXd u_start = u;
  auto fail = [&](std::string why) {
    res.failure = std::move(why);
    u = u_start;
    return res;
  };
  Eigen::VectorXd prescribed = model.constraints.increments(u, time);
  auto t0 = Clock::now();
  try {
    model.assemble(u, time, dt, prescribed, system, true);
  } catch (const ElementFailure& e) {
    return fail(e.what());
  }
  res.assembly_seconds += since(t0);
  double r_norm = system.free_residual_norm();
  double scale = std::max(r_norm, reaction_norm(model.constraints, system.residual()));
  res.residual_norms.push_back(r_norm);

  for (int it = 1; it <= settings.max_iterations; ++it) {
    res.iterations = it;
    // Linear solve in local (frame) coordinates, then back to global.
    Eigen::VectorXd du;
    t0 = Clock::now();
    LinearSolveStats ls;
    try {
      ls = linear.solve(system.matrix(), system.rhs(), du);
    } catch (const InputError&) {
      throw;  // a set-up the scene must change (e.g. AMG on a model it cannot describe): no step cut helps
    } catch (const std::exception& e) {
      return fail(fmt::format("linear solver failed: {}", e.what()));
    }
    res.linear_seconds += since(t0);
    res.linear_setup_seconds += ls.setup_seconds;
    res.linear_iterations += ls.iterations;
    if (!du.allFinite()) return fail("linear solver returned a non-finite increment");
    if (!ls.converged) log::warn("linear solver did not converge: relative residual {:.2e} after {} iterations",
                                 ls.relative_residual, ls.iterations);
    model.constraints.to_global(du);

    // Backtracking line search on |R_free|; fixed DOFs always take their full increment.
    Eigen::VectorXd du_fixed = prescribed;
    model.constraints.to_global(du_fixed);  // global-frame vector of the prescribed part
    double alpha = 1.0, best_norm = std::numeric_limits<double>::infinity(), best_alpha = 0.0;
    std::string last_failure;
    const Eigen::VectorXd u_it = u;
    for (int ls_step = 0; ls_step <= settings.line_search_steps; ++ls_step, alpha *= 0.5) {
      const Eigen::VectorXd step = alpha * (du - du_fixed) + du_fixed;
      const Eigen::VectorXd u_try = u_it + step;
      model.trial(step);
      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(u.size());
      t0 = Clock::now();
      try {
        model.assemble(u_try, time, dt, zero, system, false);
      } catch (const ElementFailure& e) {
        last_failure = e.what();
        res.assembly_seconds += since(t0);
        continue;
      }
      res.assembly_seconds += since(t0);
      const double n_try = system.free_residual_norm();
      if (!std::isfinite(n_try)) {
        last_failure = "non-finite residual";
        continue;
      }
      if (n_try < best_norm) best_norm = n_try, best_alpha = alpha;
      if (n_try <= (1.0 - 1e-4 * alpha) * r_norm) break;
    }
    if (best_alpha == 0.0) return fail(last_failure.empty() ? "line search found no admissible state" : last_failure);
    const Eigen::VectorXd step = best_alpha * (du - du_fixed) + du_fixed;
    u = u_it + step;
    model.trial(step);
    model.accept();
    prescribed.setZero();
    // Tangent at the accepted state (also re-evaluates the residual there).
    t0 = Clock::now();
    try {
      model.assemble(u, time, dt, prescribed, system, true);
    } catch (const ElementFailure& e) {
      return fail(e.what());
    }
    res.assembly_seconds += since(t0);
    r_norm = system.free_residual_norm();
    scale = std::max(scale, reaction_norm(model.constraints, system.residual()));
    res.residual_norms.push_back(r_norm);
    const double du_norm = step.norm();
    const bool r_ok = r_norm <= settings.residual_tolerance * scale + settings.residual_absolute;
    const bool du_ok = du_norm <= settings.increment_tolerance * std::max(u.norm(), 1e-12) ||
                       du_norm <= settings.increment_absolute || r_norm == 0.0;
    log::debug("  newton {}: |R| = {:.3e} (scale {:.3e}), |du| = {:.3e}, alpha = {:g}, linear its {}{}", it, r_norm,
               scale, du_norm, best_alpha, ls.iterations,
               ls.amg_levels > 0 ? fmt::format(" (AMG levels {})", ls.amg_levels) : std::string());
    // Round-off floor: an increment at machine precision cannot improve the state
    // further (tiny loads on stiff models leave |R| just above an absolute tolerance).
    // Only after a linear solve that converged: a failed Krylov solve can return
    // a near-zero increment from a state far from equilibrium.
    const bool stagnated = du_norm <= 1e-13 * std::max(u.norm(), 1e-300) && it > 1 && ls.converged;
    if ((r_ok && du_ok) || stagnated) {
      res.converged = true;
      return res;
    }
    if (!std::isfinite(r_norm) || r_norm > 1e10 * std::max(scale, 1e-30)) return fail("residual diverges");
  }
  return fail(fmt::format("no convergence in {} iterations (|R| = {:.3e})", settings.max_iterations, r_norm));
}

}  // namespace stentsim::solver
