#pragma once
// Adaptive load stepping in pseudo-time: a step that fails (no convergence,
// too many iterations, an element that cannot be evaluated) is rolled back
// and cut; easy steps let the step grow. Steps end exactly on `stops` (phase
// ends, output times); the step after one that ends on a load turn (a time
// where a load curve changes slope) starts again from dt_initial.
//
// Predictor (NewtonSettings::predictor): each attempt starts from the last
// converged step's increment scaled by h / h_last, a secant extrapolation of
// the load path; newton_step judges it (newton.hpp).
//
// Stall rule (DESIGN.md §7, issue 11 "Stability"): the stepper gives up when
//  - a cut would go below dt_min, or
//  - one step needed more than max_cuts cuts, or
//  - more than max_consecutive_cuts cuts happened since the last easy step
//    (one that converged at its first try within easy_iterations and let the
//    step grow). This catches the creep towards a limit load, where every step
//    converges only after a cut and dt shrinks geometrically without end
//    (the tube above its asymptotic pressure crept at dt 1.4e-6 for ever).
// It then throws LoadStepStall (a ComputeError) with the last converged time;
// u holds the last converged solution.
#include <Eigen/Core>

#include <functional>
#include <string>
#include <vector>

#include "common/error.hpp"
#include "solver/nonlinear/newton.hpp"

namespace stentsim::solver {

struct StepperSettings {
  double t_start = 0.0, t_end = 1.0;
  double dt_initial = 0.1, dt_min = 1e-5, dt_max = 0.1;
  int max_cuts = 8;            // cuts within one step before giving up
  int max_consecutive_cuts = 12;  // cuts since the last easy (growing) step before giving up
  double cut_factor = 0.5, grow_factor = 1.5;
  int easy_iterations = 5;     // grow after a step with at most this many Newton iterations
                               // (at the residual floor: not counting the floor_iterations that confirmed it)
  std::vector<double> stops;   // times a step must end on
  // Stops where a load curve changes slope: the next load may act quite
  // differently (the balloon's inflation after the artery's prestress), so the
  // step grown on the last one starts again from dt_initial.
  std::vector<double> load_turns;
  double dt_first = 0.0;       // the first step's size (a restart's next dt); 0: dt_initial
  int first_step = 0;          // steps done before t_start (restart: numbering continues)
  /// The predictor's start (restart): the last converged step's increment and size.
  Eigen::VectorXd last_increment;
  double last_dt = 0.0;
  /// Describes the load at pseudo-time t for the stall message, e.g.
  /// "p = 0.193 MPa (load factor 0.667)"; default "t = ...".
  std::function<std::string(double)> describe_load;
};

/// The stepper found no converged state beyond `time` (see the stall rule above).
class LoadStepStall : public ComputeError {
 public:
  LoadStepStall(const std::string& what, double time, double dt) : ComputeError(what), time(time), dt(dt) {}
  double time;  // last converged pseudo-time
  double dt;    // the step size that failed last
  // The stalled step's failed attempts, which no StepRecord reports: a run's
  // totals (summary.yaml, issue 11's stability table) add these.
  int newton_iterations = 0, linear_iterations = 0, cuts = 0;
};

struct StepRecord {
  int step = 0;
  double time = 0.0, dt = 0.0;
  int newton_iterations = 0, linear_iterations = 0, cuts = 0;  // every attempt of the step, the cut ones included
  double wall_seconds = 0.0, assembly_seconds = 0.0, linear_seconds = 0.0;
  double linear_setup_seconds = 0.0;  // part of linear_seconds: matrix build, factorization / preconditioner
  double next_dt = 0.0;        // the step size the stepper tries next (restart resumes with it)
  bool predicted = false;      // the converged attempt started from the predictor's guess
  bool at_floor = false;       // ... converged at the residual floor (newton.hpp)
  double residual_at_floor = 0.0, force_magnitude = 0.0;  // its |R| and |m| [N]
  Eigen::VectorXd increment;   // the step's increment (the next step's predictor; checkpointed)
  std::vector<double> residual_norms;
};

/// Runs from t_start to t_end. `on_step` is called after each converged and
/// committed step (u holds the new state).
void run_load_steps(Model& model, GlobalSystem& system, LinearSolver& linear, Eigen::VectorXd& u,
                    const StepperSettings& stepping, const NewtonSettings& newton,
                    const std::function<void(const StepRecord&)>& on_step);

}  // namespace stentsim::solver
