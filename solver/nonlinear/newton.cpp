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

// Norms of v over the free DOFs of each DOF owner (body, condition), in DofMap::ranges() order.
std::vector<double> norms_by_owner(const Model& model, const Eigen::VectorXd& v) {
  std::vector<double> out;
  for (const auto& range : model.dofs.ranges()) {
    double s = 0.0;
    for (GlobalDof d = range.first; d < range.first + range.count; ++d)
      if (!model.constraints.fixed(d)) s += v(d) * v(d);
    out.push_back(std::sqrt(s));
  }
  return out;
}

// The free residual per DOF owner and the DOF where it is largest: which part of a coupled
// model holds Newton back.
std::string residual_by_owner(const Model& model, const Eigen::VectorXd& r) {
  std::string out;
  const std::vector<double> parts = norms_by_owner(model, r);
  for (std::size_t k = 0; k < parts.size(); ++k)
    out += fmt::format("{}{} {:.2e}", out.empty() ? "" : ", ", model.dofs.ranges()[k].owner, parts[k]);
  double worst = -1.0;
  GlobalDof worst_dof = 0;
  for (GlobalDof d = 0; d < r.size(); ++d)
    if (!model.constraints.fixed(d) && std::abs(r(d)) > worst) worst = std::abs(r(d)), worst_dof = d;
  if (worst >= 0.0) out += fmt::format("; largest {:.2e} at DOF {} ({})", worst, worst_dof, model.dofs.owner_of(worst_dof));
  return out;
}

// The residual floor's bound (newton.hpp), part by part: each owner's residual within
// `tolerance` of its own forces in balance, or within the residual test's `bound`, so that
// a stiff body's large internal forces cannot cover a residual left in a soft one.
bool within_floor(const Model& model, const GlobalSystem& system, double tolerance, double bound) {
  const std::vector<double> r = norms_by_owner(model, system.residual()), m = norms_by_owner(model, system.force_magnitudes());
  for (std::size_t k = 0; k < r.size(); ++k)
    if (r[k] > tolerance * m[k] && r[k] > bound) {
      log::debug("  not at a residual floor: '{}' has |R| = {:.3e} against forces in balance {:.3e}", model.dofs.ranges()[k].owner,
                 r[k], m[k]);
      return false;
    }
  return true;
}
}  // namespace

NewtonResult newton_step(Model& model, GlobalSystem& system, LinearSolver& linear, Eigen::VectorXd& u, double time,
                         double dt, const NewtonSettings& settings, const Eigen::VectorXd* guess) {
  // The forcing term is this step's: the solver's own tolerance again on every way out.
  struct RestoreTolerance {
    LinearSolver& linear;
    ~RestoreTolerance() { linear.set_relative_tolerance(0.0); }
  } restore{linear};
  NewtonResult res;
  const Eigen::VectorXd u_start = u;
  auto fail = [&](std::string why) {
    res.failure = std::move(why);
    u = u_start;
    return res;
  };
  // One timed assembly at v; the failure of a term that cannot evaluate v, empty on success.
  auto assemble_at = [&](const Eigen::VectorXd& v, const Eigen::VectorXd& presc, bool tangent) -> std::string {
    const auto start = Clock::now();
    std::string failure;
    try {
      model.assemble(v, time, dt, presc, system, tangent);
    } catch (const ElementFailure& e) {
      failure = e.what();
    }
    res.assembly_seconds += since(start);
    return failure;
  };
  Eigen::VectorXd prescribed = model.constraints.increments(u, time);
  // Only for steps that no prescribed DOF drives: with fixed DOFs still at their old values the
  // slope test below would judge the guess against the wrong state.
  const bool try_guess = guess && guess->size() == u.size() && guess->squaredNorm() > 0.0 && prescribed.squaredNorm() == 0.0;
  if (std::string e = assemble_at(u, prescribed, !try_guess); !e.empty()) return fail(e);
  double r_norm = system.free_residual_norm();
  double scale = std::max(r_norm, reaction_norm(model.constraints, system.residual()));
  res.increment = Eigen::VectorXd::Zero(u.size());
  if (try_guess) {
    // The guess moves free DOFs only: fixed ones reach their values through the first solve.
    Eigen::VectorXd g_local = *guess;
    model.constraints.to_local(g_local);
    for (GlobalDof d = 0; d < g_local.size(); ++d)
      if (model.constraints.fixed(d)) g_local(d) = 0.0;
    // The potential's slope along the guess, E'(a) = R(u + a g) . g, judges it (a residual
    // norm would not: a guess ten times closer to the solution can have a larger residual in
    // the stiff directions the converged state has in balance). E'(0) >= 0: the guess points
    // against the load (it reversed). Otherwise the secant minimizer a* = E'(0) / (E'(0) - E'(1))
    // scales a guess that overshoots by more than twice.
    const double s0 = system.residual().dot(g_local);
    double scale_guess = s0 < 0.0 ? 1.0 : 0.0;
    bool kept = false;
    for (int attempt = 0; attempt < 2 && scale_guess > 0.0; ++attempt) {
      Eigen::VectorXd g = scale_guess * g_local;
      model.constraints.to_global(g);
      model.trial(g);
      const Eigen::VectorXd u_guess = u + g;
      if (std::string e = assemble_at(u_guess, prescribed, true); !e.empty()) {
        log::debug("  predictor: {} at the guess", e);
        break;
      }
      const double r_guess = system.free_residual_norm();
      if (!std::isfinite(r_guess)) break;
      const double s1 = system.residual().dot(g_local) * scale_guess;
      const double a_star = s1 > s0 * scale_guess ? -s0 * scale_guess / (s1 - s0 * scale_guess) : 1.0;
      if (attempt == 0 && a_star < 0.5) {
        scale_guess *= a_star;
        if (scale_guess < 0.05) break;  // next to nothing left of the guess: start from the converged state
        continue;
      }
      u = u_guess;
      res.increment = g;
      res.predicted = kept = true;
      log::debug("  predictor: guess x {:.3g}, |R| = {:.3e} there, {:.3e} at the converged state", scale_guess, r_guess, r_norm);
      r_norm = r_guess;
      break;
    }
    if (!kept) {
      log::debug("  predictor: {}; starting from the converged state",
                 s0 >= 0.0 ? "the guess points against the load" : "the guess does not help");
      model.trial(Eigen::VectorXd::Zero(u.size()));
      if (std::string e = assemble_at(u, prescribed, true); !e.empty()) return fail(e);
    }
    model.accept();
  }
  res.residual_norms.push_back(r_norm);

  int steady = 0;               // consecutive iterations that kept floor_reduction of |R| and changed no active set (floor test)
  double prev_du_norm = 0.0;    // the last iteration's correction
  bool prev_full_step = false;  // ... and whether the line search took all of it
  double eta = 0.0, prev_r_norm = 0.0;  // the forcing term of the last solve and the residual it started from
  for (int it = 1; it <= settings.max_iterations; ++it) {
    res.iterations = it;
    if (settings.inexact) {
      // Eisenstat-Walker choice 2 with its safeguard (header), then Kelley's bound
      // eta = min(eta_max, max(eta, 0.5 tau / |R|)) with tau the residual test's bound:
      // never tighter than the residual test needs, never looser than eta_max (once |R| is
      // within tau the solve serves the increment test, whose soft modes a loose solve
      // would not resolve).
      constexpr double eta_max = 1e-2, gamma = 0.9;
      double e = eta_max;
      if (it > 1 && prev_r_norm > 0.0) {
        e = gamma * std::pow(r_norm / prev_r_norm, 2);
        if (gamma * eta * eta > 0.1) e = std::max(e, gamma * eta * eta);
      }
      const double tau = settings.residual_tolerance * scale + settings.residual_absolute;
      if (r_norm > 0.0) e = std::max(e, 0.5 * tau / r_norm);
      eta = std::min(e, eta_max);
      if (!linear.set_relative_tolerance(eta)) eta = 0.0;
      prev_r_norm = r_norm;
    }
    // Linear solve in local (frame) coordinates, then back to global.
    Eigen::VectorXd du;
    const auto t0 = Clock::now();
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
    // The full step is assembled with its tangent: when it is taken (the usual case near the
    // solution) no second assembly is needed.
    Eigen::VectorXd du_fixed = prescribed;
    model.constraints.to_global(du_fixed);  // global-frame vector of the prescribed part
    double alpha = 1.0, best_norm = std::numeric_limits<double>::infinity(), best_alpha = 0.0;
    std::string last_failure;
    const Eigen::VectorXd u_it = u;
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(u.size());
    double last_alpha = 0.0;   // the state the system holds (0: none evaluated)
    bool last_tangent = false;  // ... and whether with its tangent
    for (int ls_step = 0; ls_step <= settings.line_search_steps; ++ls_step, alpha *= 0.5) {
      const Eigen::VectorXd step = alpha * (du - du_fixed) + du_fixed;
      const Eigen::VectorXd u_try = u_it + step;
      model.trial(step);
      const bool with_tangent = ls_step == 0;
      last_alpha = 0.0;
      if (std::string e = assemble_at(u_try, zero, with_tangent); !e.empty()) {
        last_failure = std::move(e);
        continue;
      }
      const double n_try = system.free_residual_norm();
      if (!std::isfinite(n_try)) {
        last_failure = "non-finite residual";
        continue;
      }
      last_alpha = alpha, last_tangent = with_tangent;
      if (n_try < best_norm) best_norm = n_try, best_alpha = alpha;
      if (n_try <= (1.0 - 1e-4 * alpha) * r_norm) break;
    }
    if (best_alpha == 0.0) return fail(last_failure.empty() ? "line search found no admissible state" : last_failure);
    const Eigen::VectorXd step = best_alpha * (du - du_fixed) + du_fixed;
    u = u_it + step;
    res.increment += step;
    prescribed.setZero();
    // Tangent at the accepted state (also re-evaluates the residual there), unless the
    // system already holds it (the full step, taken). Terms see the accepted state's
    // tangent assembly before accept(): contact counts active-set changes there.
    if (!(last_tangent && last_alpha == best_alpha)) {
      model.trial(step);
      if (std::string e = assemble_at(u, prescribed, true); !e.empty()) return fail(e);
    }
    model.accept();
    const int changes = model.accepted_changes();
    const double r_before = r_norm;
    r_norm = system.free_residual_norm();
    steady = r_norm >= settings.floor_reduction * r_before && changes == 0 ? steady + 1 : 0;
    res.force_magnitude = system.force_magnitude_norm();
    scale = std::max(scale, reaction_norm(model.constraints, system.residual()));
    res.residual_norms.push_back(r_norm);
    const double du_norm = step.norm();
    // The increment test judges the error left in the new state, not the size of the
    // correction that produced it: with two full steps in a row contracting by
    // theta = |du_k| / |du_k-1| < 1, that error is at most theta / (1 - theta) |du_k|
    // (Deuflhard, Newton Methods for Nonlinear Problems, 2004, Sec. 2.1). Near the
    // solution theta ~ |du_k| (quadratic convergence), so the state after a correction
    // of 1e-5 |u| is already accurate to ~1e-10 |u| and needs no further iteration.
    double du_error = du_norm;
    if (best_alpha == 1.0 && prev_full_step && prev_du_norm > 0.0 && du_norm < prev_du_norm) {
      const double theta = du_norm / prev_du_norm;
      du_error = std::min(du_norm, theta / (1.0 - theta) * du_norm);
    }
    prev_du_norm = du_norm, prev_full_step = best_alpha == 1.0;
    const bool r_ok = r_norm <= settings.residual_tolerance * scale + settings.residual_absolute;
    const bool du_ok = du_error <= settings.increment_tolerance * std::max(u.norm(), 1e-12) ||
                       du_norm <= settings.increment_absolute || r_norm == 0.0;
    log::debug("  newton {}: |R| = {:.3e} (scale {:.3e}, forces {:.3e}), |du| = {:.3e}, alpha = {:g}, linear its {}{}{}{}{}, set-up {:.2f} s, "
               "solve {:.2f} s", it, r_norm, scale, res.force_magnitude, du_norm, best_alpha, ls.iterations,
               eta > 0.0 ? fmt::format(" to {:.1e}", eta) : std::string(),
               ls.amg_levels > 0 ? fmt::format(" (AMG levels {}{})", ls.amg_levels, ls.preconditioner_built ? ", built" : "")
                                 : std::string(),
               ls.preconditioner_lagged ? " (preconditioner lagged)" : "",
               ls.lu_factorizations > 0 ? fmt::format(" ({} LU factorization{})", ls.lu_factorizations, ls.lu_factorizations > 1 ? "s" : "")
                                        : std::string(),
               ls.setup_seconds,
               ls.solve_seconds);
    if (model.dofs.ranges().size() > 1) log::debug("    |R| by part: {}", residual_by_owner(model, system.residual()));
    // Round-off floor: an increment at machine precision cannot improve the state
    // further (tiny loads on stiff models leave |R| just above an absolute tolerance).
    // Only after a linear solve that converged: a failed Krylov solve can return
    // a near-zero increment from a state far from equilibrium.
    const bool stagnated = du_norm <= 1e-13 * std::max(u.norm(), 1e-300) && it > 1 && ls.converged;
    if ((r_ok && du_ok) || stagnated) {
      res.converged = true;
      return res;
    }
    // The residual floor (header): only for a residual above its tolerance (a state within
    // it that still moves is resolved by the increment test as before).
    if (!r_ok && settings.floor_tolerance > 0.0 && steady >= settings.floor_iterations &&
        within_floor(model, system, settings.floor_tolerance, settings.residual_tolerance * scale + settings.residual_absolute)) {
      log::debug("  converged at the residual floor: |R| = {:.3e} within {:g} of each part's forces in balance (all: {:.3e}), "
                 "each keeping at least {:g} of |R| with no active set changed, {} iterations in a row",
                 r_norm, settings.floor_tolerance, res.force_magnitude, settings.floor_reduction, steady);
      res.converged = res.at_floor = true;
      return res;
    }
    if (!std::isfinite(r_norm) || r_norm > 1e10 * std::max(scale, 1e-30)) return fail("residual diverges");
  }
  return fail(fmt::format("no convergence in {} iterations (|R| = {:.3e})", settings.max_iterations, r_norm));
}

}  // namespace stentsim::solver
