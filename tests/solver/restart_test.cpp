// Restart (issue 6): a run that resumes from a checkpoint (output.checkpoint_every)
// ends in the same state as the uninterrupted run, to 1e-10: the tube inflation
// (solid, follower pressure) and the beam roll-up (multiplicative rotations held
// by the beam term). Bad checkpoints are rejected with InputError.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "solver/app/solve.hpp"

namespace stentsim::solver {
namespace {

const std::filesystem::path kExamples = std::filesystem::path(STENTSIM_TEST_SOURCE_DIR) / "examples";

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("stentsim_restart_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

std::string with_checkpoints(std::string text, int every) {
  const std::string from = "output:\n  every: 1";
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("example has no 'output: every: 1'");
  return text.replace(at, from.size(), from + "\n  checkpoint_every: " + std::to_string(every));
}

int run(const std::filesystem::path& scene, const std::filesystem::path& out, bool restart = false,
        const std::filesystem::path& from = {}) {
  SolveOptions o;
  o.output_dir = out;
  if (restart) o.restart = from;
  return solve_scene(scene, o);
}

double max_difference(const MeshData& a, const MeshData& b, const std::string& array) {
  const DataArray& x = a.point_data.at(array);
  const DataArray& y = b.point_data.at(array);
  EXPECT_EQ(x.values.size(), y.values.size());
  double d = 0.0;
  for (std::size_t i = 0; i < x.values.size(); ++i) d = std::max(d, std::abs(x.values[i] - y.values[i]));
  return d;
}

// Runs `example` uninterrupted and from its last checkpoint (every `every` steps); compares.
void check_restart(const std::string& example, const std::string& body, int every, const std::vector<std::string>& qois,
                   const std::function<std::string(std::string)>& edit = {}) {
  const auto dir = fresh_dir(example);
  std::string text = with_checkpoints(files::read_text(kExamples / (example + ".yaml")), every);
  if (edit) text = edit(text);
  files::write_atomic(dir / "scene.yaml", text);
  ASSERT_EQ(run(dir / "scene.yaml", dir / "full"), 0);
  ASSERT_TRUE(std::filesystem::exists(dir / "full/checkpoint.bin"));
  // The "interrupted" run: its outputs up to the checkpoint, then a restart.
  std::filesystem::create_directories(dir / "resumed");
  std::filesystem::copy_file(dir / "full/checkpoint.bin", dir / "resumed/checkpoint.bin");
  ASSERT_EQ(run(dir / "scene.yaml", dir / "resumed", true), 0);

  const Summary a = Summary::read(dir / "full/summary.yaml"), b = Summary::read(dir / "resumed/summary.yaml");
  for (const auto& q : qois) {
    const auto& va = a.qois().at(q).value;
    const auto& vb = b.qois().at(q).value;
    if (std::holds_alternative<double>(va)) {
      EXPECT_NEAR(std::get<double>(va), std::get<double>(vb), 1e-10 * std::max(1.0, std::abs(std::get<double>(va)))) << q;
    } else {
      const auto& x = std::get<std::vector<double>>(va);
      const auto& y = std::get<std::vector<double>>(vb);
      ASSERT_EQ(x.size(), y.size());
      for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(x[i], y[i], 1e-10 * std::max(1.0, std::abs(x[i]))) << q;
    }
  }
  for (const char* k : {"steps", "newton_iterations"})
    EXPECT_EQ(std::get<double>(a.qois().at(k).value), std::get<double>(b.qois().at(k).value)) << k;
  EXPECT_EQ(files::read_text(dir / "full/results.pvd"), files::read_text(dir / "resumed/results.pvd"));
  // The last frame's displacements agree to 1e-10 (mm).
  const int frames = static_cast<int>(std::get<double>(a.qois().at("steps").value));
  const std::string last = "results/" + body + "_" + fmt::format("{:05d}", frames) + ".vtu";
  // The checkpoint lies before the end: the resumed run took steps and wrote the last frame itself.
  ASSERT_TRUE(std::filesystem::exists(dir / "resumed" / last)) << "the resumed run took no step: its checkpoint is the end";
  const double d = max_difference(read_vtu((dir / "full" / last).string()), read_vtu((dir / "resumed" / last).string()),
                                  "Displacement");
  // A restart that ignored the checkpoint and ran from t = 0 would pass every comparison above: the resumed run
  // must not have written the frames before its checkpoint.
  EXPECT_FALSE(std::filesystem::exists(dir / "resumed" / ("results/" + body + "_00001.vtu")))
      << "the resumed run wrote frame 1: it did not start from the checkpoint";
  std::printf("%s: restart from the last checkpoint (every %d steps) of %d steps, max |Δu| of the last frame = %.2e\n",
              example.c_str(), every, frames, d);
  EXPECT_LE(d, 1e-10);
  std::filesystem::remove_all(dir);
}

TEST(Restart, TubeInflationMatchesUninterruptedRun) { check_restart("tube_inflation", "tube", 2, {"inner_radius_at_pmax"}); }

// Viscous branch (τ = 0.5 s, β = 0.3): the checkpoint carries Q and S∞ per
// quadrature point; without them the resumed run would relax from Q = 0 and
// differ by far more than 1e-10. The stress output holds the viscous part.
TEST(Restart, ViscousTubeMatchesUninterruptedRun) {
  check_restart("tube_inflation", "tube", 2, {"inner_radius_at_pmax"}, [](std::string t) {
    const std::string from = "neo_hooke: {E: 1 MPa, nu: 0.45}";
    const auto at = t.find(from);
    if (at == std::string::npos) throw std::runtime_error("tube example: material line not found");
    return t.replace(at, from.size(), from + "\n        viscous: {tau: 0.5 s, beta: 0.3}");
  });
}

TEST(Restart, BeamRollupMatchesUninterruptedRun) {
  check_restart("beam_rollup", "cantilever", 4, {"tip_position", "tip_rotation_angle"});
}

// Contact: the active flags of the last converged state (the projection-failure rule),
// the plastic history of the ring and the viscous history of the balloon are in the checkpoint.
TEST(Restart, ContactRingOnBalloonMatchesUninterruptedRun) {
  check_restart("contact_ring_on_balloon", "stent", 12, {"D_max", "D_end", "contact_force_stent_balloon_max"}, [](std::string t) {
    for (std::string::size_type at; (at = t.find("file: data/")) != std::string::npos;)
      t.replace(at, 11, "file: " + (kExamples / "data").string() + "/");
    return t;
  });
}

TEST(Restart, RejectsAForeignOrDamagedCheckpoint) {
  const auto dir = fresh_dir("bad");
  files::write_atomic(dir / "scene.yaml", with_checkpoints(files::read_text(kExamples / "beam_rollup.yaml"), 4));
  files::write_atomic(dir / "junk.bin", "not a checkpoint");
  EXPECT_THROW(run(dir / "scene.yaml", dir, true, dir / "junk.bin"), InputError);
  // A checkpoint of another scene (other DOF count) names the entry that does not fit.
  ASSERT_EQ(run(dir / "scene.yaml", dir / "a"), 0);
  std::string other = files::read_text(dir / "scene.yaml");
  other.replace(other.find("elements: 16"), 12, "elements: 8");
  files::write_atomic(dir / "other.yaml", other);
  auto restart_error = [&](const std::string& scene, const std::filesystem::path& checkpoint) -> std::string {
    try {
      run(dir / scene, dir / ("b_" + scene), true, checkpoint);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  std::string e = restart_error("other.yaml", dir / "a/checkpoint.bin");
  EXPECT_NE(e.find("written by another scene"), std::string::npos) << e;
  EXPECT_NE(e.find("section bodies"), std::string::npos) << e;
  // The same DOFs, another material: the state would be silently wrong, so it is refused too.
  other = files::read_text(dir / "scene.yaml");
  other.replace(other.find("E: 1.0e4 MPa"), 12, "E: 2.0e4 MPa");
  files::write_atomic(dir / "stiffer.yaml", other);
  e = restart_error("stiffer.yaml", dir / "a/checkpoint.bin");
  EXPECT_NE(e.find("section bodies"), std::string::npos) << e;
  // A later end time, other outputs: the same run, resumed.
  other = files::read_text(dir / "scene.yaml");
  other.replace(other.find("end: 1, dt"), 10, "end: 1.2, dt");
  files::write_atomic(dir / "longer.yaml", other);
  EXPECT_EQ(run(dir / "longer.yaml", dir / "c", true, dir / "a/checkpoint.bin"), 0);
  // One byte changed inside the checkpoint: its checksum says so.
  std::string bytes = files::read_text(dir / "a/checkpoint.bin");
  bytes[bytes.size() / 2] ^= 0x10;
  files::write_atomic(dir / "damaged.bin", bytes);
  e = restart_error("scene.yaml", dir / "damaged.bin");
  EXPECT_NE(e.find("damaged"), std::string::npos) << e;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace stentsim::solver
