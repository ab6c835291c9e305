#include "solver/io/results_writer.hpp"

#include <fmt/format.h>

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
  // Frames the interrupted run wrote after its checkpoint are in no PVD entry now: remove them,
  // the resumed run writes its own.
  for (const auto& entry : std::filesystem::directory_iterator(dir_ / "results")) {
    const std::string name = entry.path().filename().string();
    const std::size_t end = name.size() >= 4 ? name.size() - 4 : 0, begin = name.rfind('_', end);
    if (begin == std::string::npos || name.compare(end, 4, ".vtu") != 0 || end - begin != 6) continue;
    const std::string digits = name.substr(begin + 1, 5);
    if (digits.find_first_not_of("0123456789") == std::string::npos && std::stoi(digits) >= frames_)
      std::filesystem::remove(entry.path());
  }
}

}  // namespace stentsim::solver
