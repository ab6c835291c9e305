// The case's solve stage: a small free expansion through `stentsim run`, the
// scene it writes (only what the scene needs; re-runnable by hand with
// `stentsim solve`), the quantities it reports and what makes it stale.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "common/files.hpp"
#include "common/summary.hpp"
#include "solver/app/built_model.hpp"
#include "solver/io/scene.hpp"
#include "solver/io/scene_kinds.hpp"
#include "tests/workflows/cli_runner.hpp"

namespace fs = std::filesystem;
using stentsim::Summary;
using stentsim::testing::run_stentsim;

namespace {

double qoi(const fs::path& summary, const std::string& name) {
  const auto s = Summary::read(summary);
  const auto it = s.qois().find(name);
  if (it == s.qois().end()) throw std::runtime_error(summary.string() + ": no " + name);
  return std::get<double>(it->second.value);
}

class SolveStage : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("stentsim-solve-stage-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    stentsim::files::write_atomic(dir / "fe.yaml",
                                  "name: fe-small\nscene: free-expansion\n"
                                  "device: {balloon: {length: 3 mm}, stent: {rings: 2}}\n"
                                  "simulation: {pressure_max: 0.6 MPa, load_steps: 5}\n");
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

TEST_F(SolveStage, FreeExpansionRunsThroughSolveWithOnlyTheDevice) {
  auto r = run_stentsim("run " + (dir / "fe.yaml").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path work = dir / "fe.work";
  for (const char* f : {"solve/scene.yaml", "solve/results.pvd", "solve/history.csv", "solve/summary.yaml"})
    EXPECT_TRUE(fs::exists(work / f)) << f;
  for (const char* none : {"segmentation", "centerline", "placement", "mesh", "fibers"})
    EXPECT_FALSE(fs::exists(work / none)) << none << " made for a free expansion";

  // The balloon pushes the crimped rings (1.15 mm) out; they spring back on deflation.
  const fs::path sum = work / "solve/summary.yaml";
  EXPECT_NEAR(qoi(sum, "stent_diameter_initial"), 1.15, 0.02);  // mean over all strut nodes, not only the crowns
  const double d_max = qoi(sum, "stent_diameter_max"), d_after = qoi(sum, "stent_diameter_after");
  EXPECT_GT(d_max, 1.3);
  EXPECT_LT(d_after, d_max);
  EXPECT_GT(d_after, 1.15);
  EXPECT_NEAR(qoi(sum, "recoil_percent"), 100 * (d_max - d_after) / d_max, 1e-9);
  EXPECT_EQ(qoi(sum, "stent_rings"), 2);
  EXPECT_GT(qoi(sum, "contact_line_load_max_stent_balloon_max"), 0.0);
  EXPECT_EQ(Summary::read(sum).qois().count("balloon_profile_diameter_p0_6"), 1u);

  // Only what the scene needs (DESIGN.md §3): the balloon and the stent, one beam-to-surface pair.
  const auto scene = stentsim::solver::read_scene(work / "solve/scene.yaml");
  ASSERT_EQ(scene.bodies.size(), 2u);
  EXPECT_EQ(scene.bodies[0].name, "balloon");
  EXPECT_EQ(scene.bodies[1].name, "stent");
  ASSERT_EQ(scene.contacts.size(), 1u);
  EXPECT_EQ(scene.contacts[0]->name, "stent_balloon");
  const auto model = stentsim::solver::build_model(scene);
  EXPECT_EQ(model->bodies.size(), 1u);
  EXPECT_EQ(model->bodies.count("balloon"), 1u);
  EXPECT_EQ(model->beams.size(), 1u);

  // The scene re-runs by hand to the same numbers.
  r = run_stentsim("solve " + (work / "solve/scene.yaml").string() + " --out " + (dir / "by-hand").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NEAR(qoi(dir / "by-hand/summary.yaml", "stent_diameter_max"), d_max, 1e-9);

  // Up to date; a change of the simulation section re-runs the solve, not the device.
  r = run_stentsim("run " + (dir / "fe.yaml").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("\n0 ran, "), std::string::npos) << r.out;
  stentsim::files::write_atomic(dir / "fe.yaml",
                                "name: fe-small\nscene: free-expansion\n"
                                "device: {balloon: {length: 3 mm}, stent: {rings: 2}}\n"
                                "simulation: {pressure_max: 0.6 MPa, load_steps: 5}\noutput: {every: 2}\n");
  r = run_stentsim("run " + (dir / "fe.yaml").string() + " --dry-run");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("run   solve"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("run   balloon"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("run   stent"), std::string::npos) << r.out;
}

}  // namespace
