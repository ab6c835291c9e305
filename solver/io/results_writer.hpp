#pragma once
// results/<body>_<step>.vtu per output step, results.pvd with TimeValue (the
// first frame is the initial state, so ParaView's time axis is right) and
// history.csv (one row per converged step). All files are written atomically.
#include <filesystem>
#include <string>
#include <vector>

#include "common/mesh_data.hpp"
#include "solver/terms/history_archive.hpp"

namespace stentsim::solver {

class ResultsWriter {
 public:
  explicit ResultsWriter(std::filesystem::path out_dir);
  /// Writes every body's mesh for output frame `frame` at `time` and rewrites the PVD.
  void write_frame(int frame, double time, const std::vector<std::pair<std::string, MeshData>>& bodies);
  /// history.csv: header once, then rows (rewritten atomically each time).
  void history_header(const std::vector<std::string>& columns);
  void history_row(const std::vector<double>& values);
  int frames() const { return frames_; }
  /// Restart: what has been written so far (PVD entries, history rows, frame count, last time).
  void save(HistoryArchive& out) const;
  void load(const HistoryArchive& in);
  double last_time() const { return last_time_; }

 private:
  std::filesystem::path dir_;
  void write_pvd() const;
  std::string pvd_body_, history_;
  int frames_ = 0;
  double last_time_ = -1e300;
};

}  // namespace stentsim::solver
