#pragma once
// The solve stage: builds the model of a scene (built_model.hpp), runs the
// adaptive load stepping and writes, into the output folder, results/*.vtu +
// results.pvd (TimeValue; first frame = initial state), history.csv and
// summary.yaml (the scene's QoIs and contact outputs). With
// output.checkpoint_every = N it writes checkpoint.bin (checkpoint.hpp) every
// N steps; a restart from it continues exactly as the uninterrupted run.
#include <filesystem>
#include <optional>
#include <string>

#include "common/summary.hpp"
#include "solver/io/scene.hpp"
#include "solver/linalg/linear_solver.hpp"

namespace stentsim::solver {

struct SolveOptions {
  /// Where results go; empty: the scene file's folder.
  std::filesystem::path output_dir;
  /// Overrides solver.linear.type of the scene.
  std::optional<LinearSolverType> linear_solver;
  /// Log Newton iterations (debug level) when true.
  bool verbose = false;
  /// Resume from a checkpoint (output.checkpoint_every); an empty path means
  /// <output folder>/checkpoint.bin. The scene must be the one that wrote it.
  std::optional<std::filesystem::path> restart;
  /// Overrides output.checkpoint_every of the scene (the case's solve stage sets its own).
  std::optional<int> checkpoint_every;
  /// Threads of the element loops per rank (threads.hpp); none: $STENTSIM_THREADS, else
  /// the cores over the ranks. Not part of the scene: the results agree to round-off.
  std::optional<int> threads;
};

/// Runs a parsed scene (the case pipeline calls this in-process). Returns 0 on
/// success. On a computation that cannot finish (divergence at the minimum
/// step) it writes the last converged state, history.csv and a summary with
/// status "failed", logs the reason and returns 2. `summary` receives what
/// summary.yaml holds. Bad input throws InputError naming file, field and
/// expectation.
int solve(const SceneDesc& scene, const SolveOptions& options, Summary& summary);

/// `stentsim solve FILE`: reads the scene and runs solve().
int solve_scene(const std::filesystem::path& scene_yaml, const SolveOptions& options = {});

}  // namespace stentsim::solver
