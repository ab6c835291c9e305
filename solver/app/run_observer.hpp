#pragma once
// Something that watches a run: a quantity of interest or a contact pair's
// outputs. It sees the initial state and every converged step, may add
// columns to history.csv and point arrays to the output frames, keeps its
// state in checkpoints and writes its entries into summary.yaml.
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "solver/nonlinear/load_stepper.hpp"
#include "solver/terms/history_archive.hpp"

namespace stentsim::solver {

/// How the run ended, for the summary.
struct RunEnd {
  bool completed = false;
  double time = 0.0;            // last converged pseudo-time
  const Eigen::VectorXd* u = nullptr;  // the last converged state
};

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  /// Before the first step: the initial state of a fresh run, or the restored
  /// state of a restart (`restarted`, after load()).
  virtual void start(const Eigen::VectorXd& u, bool restarted) {}
  /// After every converged, committed step.
  virtual void step(const StepRecord& r, const Eigen::VectorXd& u) = 0;
  /// history.csv columns and their values after the last step() (same length).
  virtual std::vector<std::string> history_columns() const { return {}; }
  virtual std::vector<double> history_values() const { return {}; }
  /// Point or cell arrays added to the frame meshes (by mesh name) at u.
  virtual void decorate(std::vector<std::pair<std::string, MeshData>>& meshes, const Eigen::VectorXd& u) const {}
  /// Its name in checkpoints ("<kind>/<name>"), unique in a model.
  virtual std::string checkpoint_name() const = 0;
  /// Restart: the observer's state under keys beginning with `prefix`.
  virtual void save(HistoryArchive& out, const std::string& prefix) const {}
  virtual void load(const HistoryArchive& in, const std::string& prefix) {}
  /// Its summary.yaml entries.
  virtual void summarize(Summary& summary, const RunEnd& end) const = 0;
};

/// Is `t` the time `at` (to the tolerance the stepper ends its steps on stops with)?
inline bool same_time(double t, double at, double t_end) { return std::abs(t - at) < 1e-9 * std::max(1.0, std::abs(t_end)); }

}  // namespace stentsim::solver
