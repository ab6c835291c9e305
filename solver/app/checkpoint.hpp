#pragma once
// The solver's own part of checkpoint.bin (HistoryArchive keys "solver/…"):
// the state vector, the time reached, the step size to try next, the last
// step's increment and size (the predictor's start) and the run's counters. Terms (Model::save_history), the results writer and the run
// observers add their parts under their own prefixes.
#include <Eigen/Core>

#include <filesystem>
#include <map>
#include <string>

#include "solver/terms/history_archive.hpp"

namespace stentsim::solver {

struct RunCounters {
  long newton_iterations = 0, linear_iterations = 0, step_cuts = 0;
  int steps = 0;
  int predicted_steps = 0;  // steps whose converged attempt started from the predictor's guess
  int floor_steps = 0;      // steps that converged at the residual floor (newton.hpp)
  double worst_floor = 0.0; // their largest |R| relative to the forces in balance
};

struct SolverCheckpoint {
  Eigen::VectorXd u;
  double time = 0.0, next_dt = 0.0;
  Eigen::VectorXd last_increment;  // empty: no predictor for the first step after the restart
  double last_dt = 0.0;
  RunCounters counters;

  void put(HistoryArchive& out) const;
  /// Reads it back; InputError (naming the checkpoint) when a field is missing or u has another size.
  static SolverCheckpoint get(const HistoryArchive& in, long long dofs);
};

struct SceneDesc;

/// Named hashes of what the state at time t depends on: the scene's bodies, conditions
/// and contact pairs (their canonical text), the contents of the files the bodies name,
/// and each load curve up to t. Not the end time, the output, the QoIs, the solver
/// settings or the rank count: a run may be resumed with more steps, other outputs or
/// on other ranks, and a curve may be extended beyond t.
/// `scene_parts`: scene_state_hashes(scene), computed once per run (it hashes the files).
std::map<std::string, std::string> state_fingerprint(const SceneDesc& scene, const std::map<std::string, std::string>& scene_parts,
                                                     double t);
/// The parts that do not depend on time: sections and files.
std::map<std::string, std::string> scene_state_hashes(const SceneDesc& scene);

/// Records it in the checkpoint ("solver/state/<part>").
void put_fingerprint(HistoryArchive& out, const std::map<std::string, std::string>& parts);
/// InputError naming the checkpoint, the scene and every part that differs (or that the
/// checkpoint lacks) when the checkpoint was written by another scene.
void check_fingerprint(const HistoryArchive& in, const std::map<std::string, std::string>& parts,
                       const std::string& checkpoint, const std::string& scene);

/// Why `file` cannot resume a run of `scene` (missing, damaged, written by another scene);
/// empty when it can. A failure to read it at all (I/O) throws.
std::string checkpoint_refusal(const SceneDesc& scene, const std::filesystem::path& file);

}  // namespace stentsim::solver
