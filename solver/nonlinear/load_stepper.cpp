#include "solver/nonlinear/load_stepper.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/terms/element_failure.hpp"

namespace stentsim::solver {

void run_load_steps(Model& model, GlobalSystem& system, LinearSolver& linear, Eigen::VectorXd& u,
                    const StepperSettings& s, const NewtonSettings& newton,
                    const std::function<void(const StepRecord&)>& on_step) {
  std::vector<double> stops = s.stops;
  stops.push_back(s.t_end);
  std::sort(stops.begin(), stops.end());
  const double eps = 1e-12 * std::max(1.0, std::abs(s.t_end));
  double t = s.t_start, dt = std::min(s.dt_first > 0.0 ? s.dt_first : s.dt_initial, s.dt_max);
  int step = s.first_step;
  int cuts_since_easy = 0;  // the stall counter: cuts since the last easy step
  Eigen::VectorXd last_increment = s.last_increment;
  double last_h = s.last_dt;
  const auto run_start = std::chrono::steady_clock::now();
  while (t < s.t_end - eps) {
    const double next_stop = *std::upper_bound(stops.begin(), stops.end(), t + eps);
    int cuts = 0;
    StepRecord rec;
    const auto t0 = std::chrono::steady_clock::now();
    for (;;) {
      double h = std::min(dt, next_stop - t);
      if (next_stop - (t + h) < 0.01 * h) h = next_stop - t;  // no sliver steps before a stop
      NewtonResult nr;
      Eigen::VectorXd guess;
      if (newton.predictor && last_h > 0.0 && last_increment.size() == u.size()) guess = (h / last_h) * last_increment;
      const Eigen::VectorXd u_start = u;  // a rejected converged state goes back to it
      try {
        model.begin_step(u, t + h, h);
        nr = newton_step(model, system, linear, u, t + h, h, newton, &guess);
      } catch (const ElementFailure& e) {
        nr.failure = e.what();  // a term could not prepare the step (e.g. a contact search): cut it
      }
      rec.newton_iterations += nr.iterations;
      rec.linear_iterations += nr.linear_iterations;
      rec.assembly_seconds += nr.assembly_seconds;
      rec.linear_seconds += nr.linear_seconds;
      rec.linear_setup_seconds += nr.linear_setup_seconds;
      if (nr.converged) {
        if (std::string why = model.rejects(u, t + h, h); !why.empty()) {
          nr.converged = false;
          nr.failure = "converged to a state that cannot be accepted: " + why;
          u = u_start;
        }
      }
      if (nr.converged) {
        model.commit();
        t += h;
        rec.dt = h;
        rec.residual_norms = nr.residual_norms;
        rec.predicted = nr.predicted;
        rec.at_floor = nr.at_floor;
        rec.residual_at_floor = nr.at_floor ? nr.residual_norms.back() : 0.0;
        rec.force_magnitude = nr.force_magnitude;
        if (guess.size() == nr.increment.size())
          log::debug("  predictor: |increment| = {:.3e}, |guess| = {:.3e}, |increment - guess| = {:.3e}", nr.increment.norm(),
                     guess.norm(), (nr.increment - guess).norm());
        last_increment = nr.increment;
        last_h = h;
        // A step taken at the residual floor spent its last floor_iterations confirming that
        // no iteration lowers |R| further: its difficulty is the iterations that reached it.
        const int work = nr.at_floor ? std::max(1, nr.iterations - newton.floor_iterations) : nr.iterations;
        if (work <= s.easy_iterations && cuts == 0) {
          dt = std::min(dt * s.grow_factor, s.dt_max);
          cuts_since_easy = 0;
        }
        if (std::any_of(s.load_turns.begin(), s.load_turns.end(), [&](double turn) { return std::abs(t - turn) <= eps; }))
          dt = std::min(dt, s.dt_initial);
        break;
      }
      model.rollback();
      ++cuts;
      ++cuts_since_easy;
      dt = h * s.cut_factor;
      std::string why;
      if (dt < s.dt_min) why = fmt::format("the next step {:.3g} would be below dt_min = {:.3g}", dt, s.dt_min);
      else if (cuts > s.max_cuts) why = fmt::format("{} cuts in one step (max_cuts = {})", cuts, s.max_cuts);
      else if (cuts_since_easy > s.max_consecutive_cuts)
        why = fmt::format("{} cuts since the last easy step (max_consecutive_cuts = {})", cuts_since_easy,
                          s.max_consecutive_cuts);
      if (!why.empty()) {
        const std::string load = s.describe_load ? s.describe_load(t) : fmt::format("t = {:.6g}", t);
        LoadStepStall stall(fmt::format("no converged state beyond {}: the step of size {:.3g} to t = {:.6g} failed "
                                        "and {}; last reason: {}",
                                        load, h, t + h, why, nr.failure),
                            t, h);
        stall.newton_iterations = rec.newton_iterations;
        stall.linear_iterations = rec.linear_iterations;
        stall.cuts = cuts;
        throw stall;
      }
      log::warn("step at t = {:.6g} (dt = {:.3g}) failed: {}; cutting to dt = {:.3g}", t + h, h, nr.failure, dt);
    }
    rec.step = ++step;
    rec.time = t;
    rec.cuts = cuts;
    rec.next_dt = dt;
    rec.increment = last_increment;
    rec.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count();
    const double eta = t > s.t_start ? elapsed * (s.t_end - t) / (t - s.t_start) : 0.0;
    // The progress line names the load reached (issue 6), e.g. "p = 0.12 MPa", when the scene can describe it.
    const std::string load = s.describe_load ? s.describe_load(t) : fmt::format("t = {:.4g}", t);
    log::info("step {} {} dt = {:.3g}: {} Newton its, {} linear its, {} cuts, {:.2f} s, ETA {:.0f} s{}", step, load,
              rec.dt, rec.newton_iterations, rec.linear_iterations, cuts, rec.wall_seconds, eta,
              rec.at_floor ? fmt::format("; at the residual floor |R| = {:.2e} ({:.1e} of the forces in balance)",
                                         rec.residual_at_floor, rec.residual_at_floor / rec.force_magnitude)
                           : std::string());
    on_step(rec);
  }
}

}  // namespace stentsim::solver
