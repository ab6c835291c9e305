#pragma once
// The solve stage: reads a scene (solver/io/scene.hpp), builds the model,
// runs the adaptive load stepping and writes, into the output folder,
// results/*.vtu + results.pvd (TimeValue; first frame = initial state),
// history.csv and summary.yaml (the scene's QoIs, e.g. inner_radius_at_pmax).
// With output.checkpoint_every = N it writes checkpoint.bin (u, every term's
// committed history, the stepper's next step size, outputs so far) every N
// steps; a restart from it continues exactly as the uninterrupted run.
#include <filesystem>
#include <optional>
#include <string>

namespace stentsim::solver {

struct SolveOptions {
  /// Where results go; empty: the scene file's folder.
  std::filesystem::path output_dir;
  /// Overrides solver.linear.type of the scene ("direct", "gmres_ilu", "gmres_amg", "eigen_lu").
  std::optional<std::string> linear_solver;
  /// Log Newton iterations (debug level) when true.
  bool verbose = false;
  /// Resume from a checkpoint (output.checkpoint_every); an empty path means
  /// <output folder>/checkpoint.bin. The scene must be the one that wrote it.
  std::optional<std::filesystem::path> restart;
};

/// Runs the scene. Returns 0 on success. On a computation that cannot
/// finish (divergence at the minimum step) it writes the last converged
/// state, history.csv and a summary.yaml with status "failed", logs the
/// reason and returns 2. Bad input throws InputError naming file, field and
/// expectation (the CLI prints it and exits non-zero).
int solve_scene(const std::filesystem::path& scene_yaml, const SolveOptions& options = {});

}  // namespace stentsim::solver
