#include "solver/io/results_writer.hpp"

#include <fmt/format.h>

#include <set>
#include <vector>

#include "common/files.hpp"

namespace stentsim::solver {

ResultsWriter::ResultsWriter(std::filesystem::path out_dir) : dir_(std::move(out_dir)) {
  std::filesystem::create_directories(dir_ / "results");
}

void ResultsWriter::write_frame(int frame, double time, const std::vector<std::pair<std::string, MeshData>>& bodies) {
  int part = 0;
  for (const auto& [name, mesh] : bodies) {
    const std::string rel = fmt::format("results/{}_{:05d}.vtu", name, frame);
    write_vtu((dir_ / rel).string(), mesh);
    pvd_body_ += fmt::format("    <DataSet timestep=\"{:.10g}\" group=\"\" part=\"{}\" name=\"{}\" file=\"{}\"/>\n", time, part++, name, rel);
  }
  ++frames_;
  last_time_ = time;
  write_pvd();
}

void ResultsWriter::write_pvd() const {
  files::write_atomic(dir_ / "results.pvd", "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n" +
                                                pvd_body_ + "  </Collection>\n</VTKFile>\n");
}

void ResultsWriter::history_header(const std::vector<std::string>& columns) {
  history_ = fmt::format("{}\n", fmt::join(columns, ","));
  files::write_atomic(dir_ / "history.csv", history_);
}

void ResultsWriter::history_row(const std::vector<double>& values) {
  std::vector<std::string> cells;
  for (double v : values) cells.push_back(fmt::format("{:.10g}", v));
  history_ += fmt::format("{}\n", fmt::join(cells, ","));
  files::write_atomic(dir_ / "history.csv", history_);
}

void ResultsWriter::save(HistoryArchive& out) const {
  out.put_text("results/pvd", pvd_body_);
  out.put_text("results/history", history_);
  out.put("results/frames", static_cast<double>(frames_));
  out.put("results/last_time", last_time_);
}

void ResultsWriter::load(const HistoryArchive& in) {
  pvd_body_ = in.get_text("results/pvd");
  history_ = in.get_text("results/history");
  frames_ = static_cast<int>(in.get_scalar("results/frames"));
  last_time_ = in.get_scalar("results/last_time");
  files::write_atomic(dir_ / "history.csv", history_);
  // What the interrupted run wrote after its checkpoint (later frames, a frame cut short)
  // is in no PVD entry now: removed, and the PVD is the checkpoint's again.
  std::set<std::string> listed;
  for (std::size_t at = pvd_body_.find("file=\"results/"); at != std::string::npos; at = pvd_body_.find("file=\"results/", at + 1)) {
    const std::size_t begin = at + 14, end = pvd_body_.find('"', begin);
    listed.insert(pvd_body_.substr(begin, end - begin));
  }
  std::vector<std::filesystem::path> stale;
  for (const auto& entry : std::filesystem::directory_iterator(dir_ / "results"))
    if (!listed.count(entry.path().filename().string())) stale.push_back(entry.path());
  for (const auto& f : stale) std::filesystem::remove_all(f);
  write_pvd();
}

}  // namespace stentsim::solver
