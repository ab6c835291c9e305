// The contact outputs a user reads agree with one another and with the law
// that made them: the beam VTU's line load, gap and projection arrays, the
// slave surface's pressure arrays, history.csv's force column and the
// summary.yaml entries, on two small scenes that converge (the strut of
// examples/studies/stability/strut_off_edge.yaml pressed 0.02 mm into its
// block and not yet slid; the blocks of examples/contact_blocks.yaml).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>

#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "solver/app/solve.hpp"

namespace stentsim::solver {
namespace {

const std::filesystem::path kExamples = std::filesystem::path(STENTSIM_TEST_SOURCE_DIR) / "examples";

double qoi(const Summary& s, const std::string& key) { return std::get<double>(s.qois().at(key).value); }

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("stentsim_contact_outputs_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// `scene` with each (from, to) replaced once, written to dir/scene.yaml.
std::filesystem::path edited(const std::filesystem::path& scene, const std::filesystem::path& dir,
                             const std::vector<std::pair<std::string, std::string>>& edits) {
  std::string text = files::read_text(scene);
  for (const auto& [from, to] : edits) {
    const auto at = text.find(from);
    if (at == std::string::npos) throw std::runtime_error(scene.string() + ": '" + from + "' not found");
    text.replace(at, from.size(), to);
  }
  files::write_atomic(dir / "scene.yaml", text);
  return dir / "scene.yaml";
}

/// Solves `scene` into dir/out and returns its summary.
Summary solved(const std::filesystem::path& scene, const std::filesystem::path& dir) {
  SolveOptions o;
  o.output_dir = dir / "out";
  EXPECT_EQ(solve_scene(scene, o), 0);
  return Summary::read(dir / "out/summary.yaml");
}

/// The last row of history.csv as column -> value.
std::map<std::string, double> last_history_row(const std::filesystem::path& file) {
  std::istringstream in(files::read_text(file));
  std::string header, line, last;
  std::getline(in, header);
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::map<std::string, double> row;
  std::istringstream h(header), v(last);
  for (std::string name, value; std::getline(h, name, ',') && std::getline(v, value, ',');) row[name] = std::stod(value);
  return row;
}

/// The last frame of `body` in results/.
MeshData last_frame(const std::filesystem::path& out, const std::string& body) {
  std::string last;
  for (const auto& e : std::filesystem::directory_iterator(out / "results")) {
    const std::string name = e.path().filename().string();
    if (name.rfind(body + "_", 0) == 0 && e.path().extension() == ".vtu" && name > last) last = name;
  }
  EXPECT_FALSE(last.empty()) << "no frame of " << body;
  return read_vtu((out / "results" / last).string());
}

TEST(ContactOutputs, BeamLineLoadGapAndForceAgreeAcrossVtuHistoryAndSummary) {
  const auto dir = fresh_dir("beam");
  const auto scene = edited(kExamples / "studies/stability/strut_off_edge.yaml", dir,
                            {{"end: 3,", "end: 1,"}, {"every: 5", "every: 1"}});
  const Summary s = solved(scene, dir);
  const double q_max = qoi(s, "contact_line_load_max_strut_block"), force = qoi(s, "contact_force_strut_block");
  const double eps = 10.0, R = 0.06;

  // history.csv's last row is the summary's end state (10 significant digits).
  const auto row = last_history_row(dir / "out/history.csv");
  ASSERT_TRUE(row.count("contact_strut_block_force"));
  EXPECT_NEAR(row.at("contact_strut_block_force"), force, 1e-9 * force);
  EXPECT_EQ(row.at("contact_strut_block_active_points"), qoi(s, "contact_active_points_strut_block"));

  const MeshData m = last_frame(dir / "out", "strut");
  const DataArray& load = m.point_data.at("ContactLineLoad_strut_block");
  const DataArray& mag = m.point_data.at("ContactLineLoadMagnitude_strut_block");
  const DataArray& gap = m.point_data.at("ContactGap_strut_block");
  const DataArray& projected = m.point_data.at("ContactProjected_strut_block");
  ASSERT_EQ(load.components, 3);
  ASSERT_EQ(mag.tuples(), m.points.size());
  double vtu_max = 0.0;
  int loaded = 0;
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const double q = mag.at(i), y = m.points[i].y();
    EXPECT_NEAR(std::hypot(load.at(i, 0), load.at(i, 1), load.at(i, 2)), q, 1e-12 + 1e-9 * q);
    vtu_max = std::max(vtu_max, q);
    if (y > 0.1 && y < 0.9) {  // over the block, away from its edges: projected, pressed, pushed up
      EXPECT_EQ(projected.at(i), 1.0) << "point " << i;
      EXPECT_GT(q, 0.0) << "point " << i;
      EXPECT_GT(load.at(i, 2), 0.999 * q) << "point " << i;
    }
    if (y < -R - 0.12) EXPECT_EQ(projected.at(i), 0.0) << "point " << i << " beyond the search margin";
    if (projected.at(i) == 0.0) EXPECT_EQ(gap.at(i), 0.0);
    if (q > 0.0) {
      ++loaded;
      EXPECT_NEAR(gap.at(i), -q / eps, 1e-10) << "point " << i;  // linear law: q = eps <-g>
    }
  }
  EXPECT_GT(loaded, 0);
  // The frame samples the element's nearest Gauss point: its largest load is one of the summary's.
  EXPECT_LE(vtu_max, q_max * (1 + 1e-9));
  EXPECT_GT(vtu_max, 0.9 * q_max);
  // Pressed by about 0.02 mm: q ≈ eps 0.02 = 0.2 N/mm, the force about q times the 1 mm over the block.
  EXPECT_GT(q_max, 0.1);
  EXPECT_LT(q_max, 0.3);
  EXPECT_GT(force, 0.5 * q_max);
  EXPECT_LT(force, 1.5 * q_max);
  std::filesystem::remove_all(dir);
}

TEST(ContactOutputs, SlavePressureAndForceAgreeAcrossVtuHistoryAndSummary) {
  const auto dir = fresh_dir("s2s");
  std::string text = files::read_text(kExamples / "contact_blocks.yaml");
  for (std::string::size_type at; (at = text.find("file: data/")) != std::string::npos;)
    text.replace(at, 11, "file: " + (kExamples / "data").string() + "/");
  files::write_atomic(dir / "scene.yaml", text);
  const Summary s = solved(dir / "scene.yaml", dir);
  const double p_max = qoi(s, "contact_pressure_max_interface"), force = qoi(s, "contact_force_interface");
  const auto row = last_history_row(dir / "out/history.csv");
  ASSERT_TRUE(row.count("contact_interface_force"));
  EXPECT_NEAR(row.at("contact_interface_force"), force, 1e-9 * force);
  EXPECT_EQ(row.at("contact_interface_active_nodes"), qoi(s, "contact_active_nodes_interface"));
  const MeshData m = last_frame(dir / "out", "upper");
  // 0.1 MPa follower pressure over the current interface, which the blocks' lateral expansion
  // grew from 1 mm^2 (uniform state: the corner node (1, 1, 0.5) gives its size).
  const DataArray& disp = m.point_data.at("Displacement");
  double area = 0.0;
  for (std::size_t i = 0; i < m.points.size(); ++i)
    if ((m.points[i] - Eigen::Vector3d(1.0, 1.0, 0.5)).norm() < 1e-9) area = (1.0 + disp.at(i, 0)) * (1.0 + disp.at(i, 1));
  std::printf("blocks: contact force %.6f N, 0.1 MPa x current interface %.6f mm^2 = %.6f N\n", force, area, 0.1 * area);
  EXPECT_GT(area, 1.01);
  EXPECT_NEAR(force, 0.1 * area, 2e-3 * force);

  const DataArray& slave = m.point_data.at("ContactSlave_interface");
  const DataArray& pressure = m.point_data.at("ContactPressure_interface");
  double vtu_max = 0.0;
  int on = 0;
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const bool interface = std::abs(m.points[i].z() - 0.5) < 1e-9;  // reference positions
    EXPECT_EQ(slave.at(i), interface ? 1.0 : 0.0) << "node " << i;
    if (!interface) EXPECT_EQ(pressure.at(i), 0.0) << "node " << i;
    if (interface) {
      ++on;
      EXPECT_NEAR(pressure.at(i), 0.1, 0.01) << "node " << i;
    }
    vtu_max = std::max(vtu_max, pressure.at(i));
  }
  EXPECT_EQ(on, 16);  // the upper block's 4 x 4 interface nodes (3 x 3 faces)
  EXPECT_NEAR(vtu_max, p_max, 1e-12 * p_max);
  EXPECT_EQ(m.point_data.count("ContactSlave_interface"), 1u);
  const MeshData lower = last_frame(dir / "out", "lower");
  EXPECT_EQ(lower.point_data.count("ContactPressure_interface"), 0u);  // the master carries none
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace stentsim::solver
