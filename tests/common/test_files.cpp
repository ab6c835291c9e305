#include <gtest/gtest.h>
#include <unistd.h>

#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"

namespace fs = std::filesystem;
using namespace stentsim;

TEST(Files, AtomicWriteReplacesAndHashesFollowContent) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim-files-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  files::write_atomic(dir / "a.txt", "one");
  const auto h1 = files::content_hash(dir / "a.txt");
  files::write_atomic(dir / "a.txt", "two");
  EXPECT_EQ(files::read_text(dir / "a.txt"), "two");
  EXPECT_NE(files::content_hash(dir / "a.txt"), h1);
  files::write_atomic(dir / "a.txt", "one");
  EXPECT_EQ(files::content_hash(dir / "a.txt"), h1);
  EXPECT_EQ(files::content_hash(dir / "a.txt"), files::text_hash("one"));
  // Only the target remains: no temporary files.
  int n = 0;
  for ([[maybe_unused]] auto& e : fs::directory_iterator(dir)) ++n;
  EXPECT_EQ(n, 1);
  fs::remove_all(dir);
}

TEST(Files, MeshDataRoundTripsThroughVtuAndVtp) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim-mesh-" + std::to_string(::getpid()));
  MeshData m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.add_cell(CellType::tetra, {0, 1, 2, 3});
  m.point_data["Radius"] = {1, {0.1, 0.2, 0.3, 0.4}};
  m.cell_data["Layer"] = {1, {2}};
  m.field_text["units"] = "mm";
  write_vtu((dir / "t.vtu").string(), m);
  auto r = read_vtu((dir / "t.vtu").string());
  ASSERT_EQ(r.points.size(), 4u);
  EXPECT_EQ(r.cell_types[0], CellType::tetra);
  EXPECT_EQ(r.cell(0), (std::vector<std::int64_t>{0, 1, 2, 3}));
  EXPECT_DOUBLE_EQ(r.point_data.at("Radius").at(3), 0.4);
  EXPECT_DOUBLE_EQ(r.cell_data.at("Layer").at(0), 2);
  EXPECT_EQ(r.field_text.at("units"), "mm");

  MeshData p;
  p.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  p.add_cell(CellType::triangle, {0, 1, 2});
  p.add_cell(CellType::polyline, {0, 1, 2});
  p.cell_data["Id"] = {1, {7, 8}};
  write_vtp((dir / "p.vtp").string(), p);
  auto q = read_vtp((dir / "p.vtp").string());
  ASSERT_EQ(q.num_cells(), 2u);
  // VTK stores lines before polygons: cell data follows the cells.
  EXPECT_EQ(q.cell_types[0], CellType::polyline);
  EXPECT_DOUBLE_EQ(q.cell_data.at("Id").at(0), 8);
  EXPECT_THROW(read_vtu((dir / "missing.vtu").string()), std::exception);
  fs::remove_all(dir);
}

TEST(Files, SummaryRoundTrips) {
  const fs::path f = fs::temp_directory_path() / ("stentsim-summary-" + std::to_string(::getpid()) + ".yaml");
  Summary s;
  s.set("inner_radius_at_pmax", 1.234, "mm");
  s.set("tip_position", {1.0, 2.0, 3.0}, "mm");
  s.set_run(2.5, 100.0);
  s.write(f);
  auto r = Summary::read(f);
  EXPECT_DOUBLE_EQ(std::get<double>(r.qois().at("inner_radius_at_pmax").value), 1.234);
  EXPECT_EQ(r.qois().at("inner_radius_at_pmax").unit, "mm");
  EXPECT_EQ(std::get<std::vector<double>>(r.qois().at("tip_position").value).size(), 3u);
  EXPECT_DOUBLE_EQ(r.wall_time_s(), 2.5);
  fs::remove(f);
}

// A stand-alone tool that never calls set_run (`stentsim fibers`, `mesh`)
// still reports its run: this process's lifetime and peak memory, not 0.
TEST(Files, SummaryWithoutSetRunReportsThisProcess) {
  const fs::path f = fs::temp_directory_path() / ("stentsim-summary-run-" + std::to_string(::getpid()) + ".yaml");
  std::vector<double> touch(4'000'000, 1.0);  // ~30 MB resident, so the peak is clearly nonzero
  Summary s;
  s.set("x", touch[123], "mm");
  s.write(f);
  const auto r = Summary::read(f);
  EXPECT_GT(r.wall_time_s(), 0.0);
  EXPECT_LE(r.wall_time_s(), process_wall_time_s());
  EXPECT_GT(r.peak_memory_mb(), 30.0);
  fs::remove(f);
}

TEST(Files, LogTailKeepsTheLastNonEmptyLines) {
  const fs::path f = fs::temp_directory_path() / ("stentsim-log-tail-" + std::to_string(::getpid()) + ".log");
  stentsim::files::write_atomic(f, "one\n\ntwo\nthree\n\n");
  EXPECT_EQ(stentsim::files::log_tail(f, 2), "two | three");
  EXPECT_EQ(stentsim::files::log_tail(f, 10), "one | two | three");
  EXPECT_EQ(stentsim::files::log_tail(f, 0), "");
  fs::remove(f);
  EXPECT_EQ(stentsim::files::log_tail(f, 3), "");  // missing: no text to quote
}
