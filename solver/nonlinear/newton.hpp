#pragma once
// Newton-Raphson for one load step with a backtracking line search on the
// free-DOF residual norm. A trial state that a term cannot evaluate
// (ElementFailure: inverted element, overflow, NaN) is backtracked; if no
// trial works the step fails and the stepper cuts it (DESIGN.md §7).
//
// Predictor: a step that no prescribed DOF drives may start from the last
// converged state moved by a guessed increment of its free DOFs (the stepper
// extrapolates the last step's). The potential's slope along the guess judges
// it: a guess that points against the load (a reversed load, deflation after
// inflation) is dropped, one that overshoots is shortened by a secant step,
// one that inverts an element is dropped. A dropped guess costs one or two
// extra assemblies, never the step. The force scale of the convergence test is
// the residual at the converged state whether or not the guess is kept: a good
// guess must not tighten it.
//
// Inexact Newton: a Krylov solve only needs to reduce the linear residual as
// far as the nonlinear one will follow. Iteration k stops its solve at
// |b - A du| <= eta_k |b| with Eisenstat & Walker's choice 2 (SIAM J. Sci.
// Comput. 17, 1996, Eq. 2.6 and its safeguard), eta_k = 0.9 (|R_k|/|R_k-1|)^2,
// bounded as Kelley does (1995, Sec. 6.3): eta = min(1e-2, max(eta_k, 0.5 tau / |R_k|))
// with tau the residual test's bound: far from the solution a few Krylov
// iterations, near it as accurate as quadratic convergence needs, and no
// oversolving at the end.
//
// Residual floor: a model whose residual is not smooth at the scale of the last
// corrections (element-based contact integration: each Gauss point's gap has a kink
// where its projection crosses a master edge, and frictionless sliding lets a
// small residual move the balloon far, across many of them) has a floor below
// which no Newton iteration reduces |R|. A step whose residual stays above its
// tolerance but, in every part of the model (each DOF owner: balloon, stent, artery),
// at or below floor_tolerance times that part's forces in balance (m: the per-DOF
// sums of the magnitudes of all contributions, GlobalSystem::force_magnitudes), and
// that in floor_iterations consecutive iterations keeps at least floor_reduction
// (default 0.9) of |R| and changes no contact active set
// (Term::accepted_changes: while contact points still enter or leave, the state is
// on its way, not at a floor) is taken as converged at that floor
// (NewtonResult::at_floor, counted and reported), instead of being cut: smaller
// steps do not lower a floor that the model's geometry sets. The default bound 1e-6
// is far below the residual tests of general-purpose codes (Abaqus: 5e-3 of the
// average nodal force); a scene whose floor lies in a soft body with small forces of
// its own sets a larger one (the case's solve scene: 1e-4, workflows/solve_stage.cpp). The state at the floor may still differ from the
// exact one in soft modes (the balloon's sliding), which carry little energy.
#include <Eigen/Core>

#include <string>
#include <vector>

#include "solver/assembly/model.hpp"
#include "solver/linalg/linear_solver.hpp"

namespace stentsim::solver {

struct NewtonSettings {
  int max_iterations = 20;
  double residual_tolerance = 1e-8;   // relative to the step's force scale
  double residual_absolute = 1e-10;   // N
  double increment_tolerance = 1e-8;  // relative to |u|: the error left in the state, estimated from the contraction
  double increment_absolute = 0.0;    // |du| at or below this also satisfies the increment test (0: off)
  double floor_tolerance = 1e-6;      // relative to the forces in balance |m| (0: no floor test)
  int floor_iterations = 2;           // ... after this many consecutive iterations without progress:
  double floor_reduction = 0.9;       // ... each keeping at least this fraction of |R| (Newton near a
                                      // smooth solution keeps far less; the case's solve scene sets 0.5:
                                      // the patient example's deflation creeps along its floor by 10-25 %
                                      // per damped iteration, workflows/solve_stage.cpp)
  int line_search_steps = 6;          // halvings
  bool predictor = true;              // the stepper starts each step from the last step's increment, extrapolated
  /// Krylov solvers stop at the Eisenstat-Walker forcing term instead of their fixed tolerance
  /// (which stays the tightest they are asked for); direct solvers ignore it.
  bool inexact = true;
};

struct NewtonResult {
  bool converged = false;
  int iterations = 0;
  int linear_iterations = 0;
  std::vector<double> residual_norms;  // free-DOF residual, per iteration (index 0 = before the first solve)
  std::string failure;                 // why it failed (last element failure or divergence)
  double assembly_seconds = 0.0, linear_seconds = 0.0;
  bool predicted = false;              // the step started from the predictor's guess
  bool at_floor = false;               // converged at the residual floor (header), not by the tolerance
  double force_magnitude = 0.0;        // |m| at the last iterate (header)
  /// The converged step's increment (additive DOFs exactly; rotational DOFs the
  /// sum of their rotation-vector increments, a first-order guess).
  Eigen::VectorXd increment;
  double linear_setup_seconds = 0.0;  // part of linear_seconds: matrix build, factorization / preconditioner
};

/// Solves the step ending at `time` (size dt) starting from u (updated in
/// place on success; left at the start value on failure). `guess`, when
/// given and non-empty, is the predictor's increment (global frame; its
/// components at fixed DOFs are ignored: those follow their prescribed values).
NewtonResult newton_step(Model& model, GlobalSystem& system, LinearSolver& linear, Eigen::VectorXd& u, double time,
                         double dt, const NewtonSettings& settings, const Eigen::VectorXd* guess = nullptr);

}  // namespace stentsim::solver
