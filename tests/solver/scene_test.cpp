// The solve stage from a scene file: the tube example runs, writes the PVD
// (first frame = initial state), VTUs with the stress fields, history.csv and
// summary.yaml with inner_radius_at_pmax matching the semi-analytic
// reference; bad scenes give InputError naming file and key.
#include <gtest/gtest.h>
#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "solver/app/solve.hpp"
#include "solver/materials/coupled_neo_hooke.hpp"
#include "tests/solver/tube_reference.hpp"

namespace stentsim::solver {
namespace {

const std::filesystem::path kExample = std::filesystem::path(STENTSIM_SOURCE_DIR) / "examples/tube_inflation.yaml";

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("stentsim_solver_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

TEST(SolverScene, TubeExampleMatchesReference) {
  const auto out = fresh_dir("tube");
  SolveOptions opt;
  opt.output_dir = out;
  ASSERT_EQ(solve_scene(kExample, opt), 0);
  const Summary s = Summary::read(out / "summary.yaml");
  ASSERT_TRUE(s.qois().count("inner_radius_at_pmax"));
  const double r = std::get<double>(s.qois().at("inner_radius_at_pmax").value);
  const auto nh = CoupledNeoHooke::from_young_poisson(1.0, 0.45);
  const double r_ref = test::TubeReference{nh.c, nh.beta, 0.8, 1.4}.inner_radius(0.12);
  std::printf("scene: r_i(p_max) = %.6f, reference %.6f, error %.3f %% of u_r\n", r, r_ref, 100 * std::abs(r - r_ref) / (r_ref - 0.8));
  EXPECT_LT(std::abs(r - r_ref), 0.01 * (r_ref - 0.8));
  // PVD: the first frame is the initial state at t = 0, the last at t = 1.
  const std::string pvd = files::read_text(out / "results.pvd");
  EXPECT_NE(pvd.find("timestep=\"0\""), std::string::npos);
  EXPECT_NE(pvd.find("timestep=\"1\""), std::string::npos);
  const MeshData first = read_vtu((out / "results/tube_00000.vtu").string());
  for (const char* a : {"CauchyStress", "MaxPrincipalStress", "MaxPrincipalDirection", "VonMisesStress", "GreenLagrangeStrain", "MaterialIndex"})
    EXPECT_TRUE(first.cell_data.count(a)) << a;
  EXPECT_TRUE(first.point_data.count("Displacement"));
  // history.csv: header + one row per step (8 steps of 0.125 at most).
  std::ifstream h(out / "history.csv");
  std::string line;
  int rows = -1;
  std::vector<std::string> header;
  std::vector<std::vector<double>> table;
  auto split = [](const std::string& l) {
    std::vector<std::string> cells;
    std::stringstream ss(l);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    return cells;
  };
  while (std::getline(h, line)) {
    if (++rows == 0) {
      header = split(line);
      continue;
    }
    std::vector<double> row;
    for (const auto& cell : split(line)) row.push_back(std::stod(cell));
    table.push_back(row);
  }
  EXPECT_GE(rows, 4);
  EXPECT_LE(rows, 8);
  // The documented columns in this order (history.csv of README's solver section), one per pressure condition.
  const std::vector<std::string> columns{"step", "time", "dt", "load_factor", "newton_iterations", "linear_iterations",
                                         "step_cuts", "wall_time_s", "assembly_s", "linear_solve_s", "pressure_lumen_pressure"};
  std::map<std::string, std::size_t> at;
  for (std::size_t i = 0; i < header.size(); ++i) EXPECT_TRUE(at.emplace(header[i], i).second) << "column twice: " << header[i];
  std::size_t previous = 0;
  for (const auto& c : columns) {
    ASSERT_TRUE(at.count(c)) << "history.csv lacks column " << c;
    if (&c != &columns.front()) EXPECT_GT(at[c], previous) << c << " out of order";
    previous = at[c];
  }
  ASSERT_FALSE(table.empty());
  for (const auto& row : table) ASSERT_EQ(row.size(), header.size());
  EXPECT_DOUBLE_EQ(table.back()[at["time"]], 1.0);
  EXPECT_DOUBLE_EQ(table.back()[at["load_factor"]], 1.0);         // no load_factor curve: the time
  EXPECT_NEAR(table.back()[at["pressure_lumen_pressure"]], 0.12, 1e-10);  // 0.12 MPa x ramp(1)
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_DOUBLE_EQ(table[i][at["step"]], static_cast<double>(i + 1));
    EXPECT_GE(table[i][at["newton_iterations"]], 1.0);
    EXPECT_NEAR(table[i][at["pressure_lumen_pressure"]], 0.12 * table[i][at["time"]], 1e-10);
    if (i > 0) EXPECT_NEAR(table[i][at["time"]] - table[i - 1][at["time"]], table[i][at["dt"]], 1e-9);
  }
  // Hoop stress at the inner wall is the largest principal stress and positive.
  int last = 0;
  while (std::filesystem::exists(out / fmt::format("results/tube_{:05d}.vtu", last + 1))) ++last;
  const MeshData end = read_vtu((out / fmt::format("results/tube_{:05d}.vtu", last)).string());
  double smax = 0;
  for (double v : end.cell_data.at("MaxPrincipalStress").values) smax = std::max(smax, v);
  EXPECT_GT(smax, 0.12);
  std::filesystem::remove_all(out);
}

TEST(SolverScene, BadInputNamesFileAndKey) {
  const auto dir = fresh_dir("bad");
  std::string text = files::read_text(kExample);
  auto expect_error = [&](const std::string& from, const std::string& to, const std::string& needle) {
    std::string t = text;
    const auto at = t.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    files::write_atomic(dir / "scene.yaml", t);
    try {
      SolveOptions o;
      o.output_dir = dir;
      solve_scene(dir / "scene.yaml", o);
      ADD_FAILURE() << "no error for " << to;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("scene.yaml"), std::string::npos) << msg;
      EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    }
  };
  expect_error("nu: 0.45", "nu: 0.5", "nu");
  expect_error("value: 0.12 MPa", "value: 0.12 mm", "value");
  expect_error("components: y", "components: q", "components");
  expect_error("curve: ramp", "curve: rampp", "curve");
  expect_error("radius: 0.8 mm}}\n    value", "radius: 0.7 mm}}\n    value", "selects no boundary face");
  expect_error("type: direct", "type: cholesky", "type");
  // Old spellings and misspelt kinds get the nearest name.
  expect_error("type: direct", "type: gmres-amg", "did you mean 'gmres_amg'");
  expect_error("type: pressure", "type: presure", "did you mean 'pressure'");
  expect_error("every: 1", "evry: 1", "evry");
  expect_error("newton: {max_iterations: 20,", "newton: {predictor: extrapolat, max_iterations: 20,",
               "solver.newton.predictor: 'extrapolat' is not one of: extrapolate, none (did you mean 'extrapolate'?)");
  // The decoupled form replaces the coupled matrix: both in one material is an error that says which to drop.
  expect_error("neo_hooke: {E: 1 MPa, nu: 0.45}", "neo_hooke: {E: 1 MPa, nu: 0.45}\n        decoupled_hgo: {E: 1 MPa, nu: 0.45}",
               "decoupled_hgo: replaces the coupled neo-Hooke matrix: drop 'neo_hooke'");
  // MueLu parameters only for gmres_amg, and only from a file that exists.
  expect_error("type: direct", "type: direct, amg_parameters: muelu.xml", "amg_parameters: applies to types gmres_amg and gmres_amg_block only");
  expect_error("type: direct", "type: gmres_amg, amg_parameters: muelu.xml", "amg_parameters: no such file");
  // Preconditioner lagging only for the Krylov types, with one of its two values.
  expect_error("type: direct", "type: direct, preconditioner_update: lagged", "preconditioner_update: applies to the Krylov types");
  expect_error("type: direct", "type: gmres_amg, preconditioner_update: sometimes", "preconditioner_update");
  // Generated meshes: the element count is checked before anything is allocated (10^14
  // hex8 here once overflowed an int), and a box's cells are whole positive numbers.
  expect_error("radial: 8\n        circumferential: 24\n        axial: 1",
               "radial: 10000\n        circumferential: 100000\n        axial: 100000",
               "axial: radial x circumferential x axial gives 1e+14 hex8 elements, more than the 5e+06");
  const std::string ring = "type: ring_sector          # quarter annulus about the z axis\n        inner_radius: 0.8 mm\n"
                           "        outer_radius: 1.4 mm\n        angle_deg: 90\n        height: 0.05 mm            # one layer of "
                           "elements: plane strain with u_z = 0\n        radial: 8\n        circumferential: 24\n        axial: 1\n";
  expect_error(ring, "type: box\n        size: [1, 1, 1]\n        cells: [2, -3, 2]\n", "cells: expected three whole numbers");
  expect_error(ring, "type: box\n        size: [1, 1, 1]\n        cells: [2, 2.5, 2]\n", "cells: expected three whole numbers");
  expect_error(ring, "type: box\n        size: [1, 0, 1]\n        cells: [2, 2, 2]\n", "size: expected three positive lengths");
  expect_error(ring, "type: box\n        size: [1, 1, 1]\n        cells: [1000, 1000, 100]\n",
               "cells: the product of cells gives 1e+08 hex8 elements");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace stentsim::solver
