// Stent ring expansion as a scene (issue 9): examples/stent_ring_expansion.yaml
// through solve_scene — one ring of the stent stage (16 struts), elasto-plastic
// beams (App. C stent preset), rigid crown joints (master–slave), crowns pushed
// radially 0 → 0.725 mm in 20 steps (radial_displacement) with mirror planes
// and one crown fixed axially (fix_cylindrical), then released into their last
// reactions ramped to zero in 10 steps (release).
// Criteria (issue 9): D_max = 2.6; D_end and recoil as the reference run of the
// ring (3 el/strut: D_end 2.299586 mm, recoil 11.554 %; 6 el/strut: 2.300181 mm,
// 11.531 %; from the test assembly of part 2, commit 638ed22, which prescribed
// the crowns by Dirichlet conditions instead of multipliers); the 8 peaks and
// the 8 valleys agree in radius to 1e-6; the largest ‖M_b‖ is next to a crown
// and exceeds M_y0; crowns yield; the written BendingMoment's maximum is the
// Gauss-point maximum of the summary at the peak and at the end, and no point
// yields at the end (the plastic output is the committed Gauss-point state,
// BeamTerm::sample); external work = stored + plastic work within
// 1 %; every crown joint keeps its reference kink to 1e-10 rad. Restart from a
// checkpoint in the expansion phase matches the uninterrupted run to 1e-10.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "solver/app/solve.hpp"

namespace stentsim::solver {
namespace {

const std::filesystem::path kExamples = std::filesystem::path(STENTSIM_TEST_SOURCE_DIR) / "examples";

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("stentsim_ring_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("example has no '" + from + "'");
  return text.replace(at, from.size(), to);
}

/// The example with its ring file made absolute (the scene is written elsewhere).
std::string ring_scene(int elements_per_strut, int checkpoint_every = 0) {
  std::string t = files::read_text(kExamples / "stent_ring_expansion.yaml");
  t = replaced(t, "file: data/stent_ring_3el.vtu",
               "file: " + (kExamples / fmt::format("data/stent_ring_{}el.vtu", elements_per_strut)).string());
  if (checkpoint_every > 0) t = replaced(t, "output:\n  every: 1", fmt::format("output:\n  every: 1\n  checkpoint_every: {}", checkpoint_every));
  return t;
}

double qoi(const Summary& s, const std::string& k) { return std::get<double>(s.qois().at(k).value); }

MeshData frame(const std::filesystem::path& out, int k) {
  return read_vtu((out / fmt::format("results/ring_{:05d}.vtu", k)).string());
}

Eigen::Matrix3d triad(const MeshData& m, std::size_t p) {
  Eigen::Matrix3d T;
  const char* names[3] = {"TriadD1", "TriadD2", "TriadD3"};
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i) T(i, c) = m.point_data.at(names[c]).at(p, i);
  return T;
}

struct Crown {
  std::vector<std::size_t> points;  // sample points at the crown (element ends of the elements meeting there)
  bool peak = false;
};

// Crowns: element-end sample points at the reference crown positions (r₀ = 0.575, |z₀| = 0.75).
std::vector<Crown> crowns(const MeshData& m0) {
  std::vector<Crown> c;
  for (std::size_t cell = 0; cell < m0.num_cells(); ++cell) {
    const auto ids = m0.cell(cell);
    for (auto id : {ids.front(), ids.back()}) {
      const Eigen::Vector3d x = m0.points[static_cast<std::size_t>(id)];
      if (std::abs(std::hypot(x.x(), x.y()) - 0.575) > 1e-9 || std::abs(std::abs(x.z()) - 0.75) > 1e-9) continue;
      auto it = std::find_if(c.begin(), c.end(), [&](const Crown& k) { return (m0.points[k.points[0]] - x).norm() < 1e-9; });
      if (it == c.end()) c.push_back({{static_cast<std::size_t>(id)}, x.z() > 0});
      else it->points.push_back(static_cast<std::size_t>(id));
    }
  }
  return c;
}

void check_ring(int eps, double D_end_ref, double recoil_ref) {
  const auto dir = fresh_dir(fmt::format("{}el", eps));
  files::write_atomic(dir / "scene.yaml", ring_scene(eps));
  SolveOptions o;
  o.output_dir = dir / "out";
  ASSERT_EQ(solve_scene(dir / "scene.yaml", o), 0);
  const Summary s = Summary::read(dir / "out/summary.yaml");
  const double balance = qoi(s, "energy_balance_error");
  std::printf("ring %d el/strut (scene): D0 %.6f D_max %.9f D_end %.9f mm, recoil %.6f %%, max |M_b| %.4f (peak) %.4f (end) "
              "N mm, W_ext %.6e = stored %.6e + plastic %.6e (balance error %.3e), %g DOFs, %g Newton iterations\n",
              eps, qoi(s, "D_initial"), qoi(s, "D_max"), qoi(s, "D_end"), qoi(s, "recoil_percent"),
              qoi(s, "max_bending_moment_peak"), qoi(s, "max_bending_moment_end"), qoi(s, "external_work"),
              qoi(s, "stored_energy_end"), qoi(s, "plastic_work_end"), balance, qoi(s, "dofs"), qoi(s, "newton_iterations"));
  EXPECT_NEAR(qoi(s, "D_initial"), 1.15, 1e-9);
  EXPECT_NEAR(qoi(s, "D_max"), 2.6, 1e-9);
  EXPECT_NEAR(qoi(s, "D_end"), D_end_ref, 1e-6);
  EXPECT_NEAR(qoi(s, "recoil_percent"), recoil_ref, 1e-3);
  EXPECT_GT(qoi(s, "max_bending_moment_peak"), 0.08);  // M_y0
  EXPECT_LT(qoi(s, "max_bending_moment_end"), qoi(s, "max_bending_moment_peak"));
  EXPECT_LT(balance, 0.01);
  EXPECT_EQ(qoi(s, "steps"), 30.0);
  // After release every crown reaction vanishes: the radial point forces are ramped to zero and the
  // mirror planes / axial fix carry nothing (multipliers = reactions, N).
  // (the example holds them by fix_cylindrical, Dirichlet components in nodal frames: the beam's
  // residual there; no direction condition, so that key stays 0).
  std::printf("  end reactions: radial %.3e N, mirror planes / axial fix %.3e N\n", qoi(s, "max_radial_condition_force_end"),
              qoi(s, "max_held_position_reaction_end"));
  EXPECT_LT(qoi(s, "max_radial_condition_force_end"), 1e-8);
  EXPECT_LT(qoi(s, "max_held_position_reaction_end"), 1e-8);
  EXPECT_EQ(qoi(s, "max_direction_condition_reaction_end"), 0.0);

  // The beam VTUs: crowns, peaks/valleys, joint kinks, yielding crowns.
  const MeshData m0 = frame(dir / "out", 0), mp = frame(dir / "out", 20), me = frame(dir / "out", 30);
  const auto cs = crowns(m0);
  ASSERT_EQ(cs.size(), 16u);
  double pmin = 1e300, pmax = 0, vmin = 1e300, vmax = 0, kink = 0;
  for (const Crown& c : cs) {
    ASSERT_EQ(c.points.size(), 2u);  // two struts meet at every crown
    const Eigen::Vector3d x = me.points[c.points[0]];
    const double r = std::hypot(x.x(), x.y());
    (c.peak ? pmin : vmin) = std::min(c.peak ? pmin : vmin, r);
    (c.peak ? pmax : vmax) = std::max(c.peak ? pmax : vmax, r);
    // Λ_a Λ_a0ᵀ = Λ_b Λ_b0ᵀ at the joint (the reference kink is kept)
    const Eigen::Matrix3d Ra = triad(me, c.points[0]) * triad(m0, c.points[0]).transpose();
    const Eigen::Matrix3d Rb = triad(me, c.points[1]) * triad(m0, c.points[1]).transpose();
    kink = std::max(kink, Eigen::AngleAxisd(Ra * Rb.transpose()).angle());
  }
  std::printf("  peak/valley radius spread %.1e/%.1e, joint rotation error %.1e rad\n", (pmax - pmin) / pmax,
              (vmax - vmin) / vmax, kink);
  EXPECT_LT((pmax - pmin) / pmax, 1e-6);
  EXPECT_LT((vmax - vmin) / vmax, 1e-6);
  EXPECT_LT(kink, 1e-10);
  // The written BendingMoment of the plastic ring is the committed Gauss-point
  // moment (BeamTerm::sample): its maximum is the Gauss-point maximum of the
  // summary, at the peak and at the end.
  auto array_max = [](const MeshData& m, const char* name) {
    double x = 0.0;
    for (double v : m.point_data.at(name).values) x = std::max(x, v);
    return x;
  };
  auto count_set = [](const MeshData& m, const char* name) {
    int n = 0;
    for (double v : m.point_data.at(name).values) n += v > 0.5 ? 1 : 0;
    return n;
  };
  std::printf("  max written M_b %.6f (peak) %.6f (end) N mm; yielding samples %d (peak) %d (end) of %zu\n",
              array_max(mp, "BendingMoment"), array_max(me, "BendingMoment"), count_set(mp, "Yielding"),
              count_set(me, "Yielding"), mp.points.size());
  EXPECT_NEAR(array_max(mp, "BendingMoment"), qoi(s, "max_bending_moment_peak"), 1e-9 * qoi(s, "max_bending_moment_peak"));
  EXPECT_NEAR(array_max(me, "BendingMoment"), qoi(s, "max_bending_moment_end"), 1e-9 * qoi(s, "max_bending_moment_peak"));
  EXPECT_EQ(count_set(me, "Yielding"), 0);  // no Gauss point flows while the ring is released
  // At the peak the largest (Gauss-point) ‖M_b‖ lies in an element that ends at a crown, and crowns yield
  // (Yielding: the crown's nearest Gauss point flowed in the last expansion step).
  const DataArray& Mb = mp.point_data.at("BendingMoment");
  std::size_t arg = 0;
  for (std::size_t p = 0; p < Mb.tuples(); ++p)
    if (Mb.at(p) > Mb.at(arg)) arg = p;
  bool next_to_crown = false;
  for (std::size_t cell = 0; cell < mp.num_cells(); ++cell) {
    const auto ids = mp.cell(cell);
    if (std::find(ids.begin(), ids.end(), static_cast<std::int64_t>(arg)) == ids.end()) continue;
    for (const Crown& c : cs)
      for (auto p : c.points) next_to_crown = next_to_crown || p == static_cast<std::size_t>(ids.front()) || p == static_cast<std::size_t>(ids.back());
  }
  EXPECT_TRUE(next_to_crown);
  const DataArray& y = mp.point_data.at("Yielding");
  int yielding_crowns = 0;
  for (const Crown& c : cs) yielding_crowns += y.at(c.points[0]) > 0.5 ? 1 : 0;
  EXPECT_EQ(yielding_crowns, 16);
  double eps_max = 0;
  for (std::size_t p = 0; p < me.points.size(); ++p) eps_max = std::max(eps_max, me.point_data.at("OuterFibrePlasticStrain").at(p));
  EXPECT_GT(eps_max, 0.0);
  std::filesystem::remove_all(dir);
}

[[maybe_unused]] double max_difference(const MeshData& a, const MeshData& b, const std::string& array) {
  const DataArray& x = a.point_data.at(array);
  const DataArray& y = b.point_data.at(array);
  EXPECT_EQ(x.values.size(), y.values.size());
  double d = 0.0;
  for (std::size_t i = 0; i < x.values.size(); ++i) d = std::max(d, std::abs(x.values[i] - y.values[i]));
  return d;
}

}  // namespace

// One source, two binaries (tests/solver/CMakeLists.txt): the 3 el/strut run
// and the restart are quick (CI), the 6 el/strut run is validation.
#ifndef STENTSIM_RING_VALIDATION
TEST(BeamRingScene, ExpansionAndRecoilThreeElementsPerStrut) { check_ring(3, 2.299586, 11.554); }
#else
TEST(BeamRingScene, ExpansionAndRecoilSixElementsPerStrut) { check_ring(6, 2.300181, 11.531); }
#endif

// A checkpoint at step 17 (expansion, crowns yielding) holds the plastic
// history; the run resumed from it crosses the release (t = 20, the frozen
// reactions are made after the restart) and ends as the uninterrupted run.
#ifndef STENTSIM_RING_VALIDATION
TEST(BeamRingScene, RestartFromMidExpansionMatchesUninterruptedRun) {
  const auto dir = fresh_dir("restart");
  files::write_atomic(dir / "scene.yaml", ring_scene(3, 17));
  SolveOptions full;
  full.output_dir = dir / "full";
  ASSERT_EQ(solve_scene(dir / "scene.yaml", full), 0);
  std::filesystem::create_directories(dir / "resumed");
  std::filesystem::copy_file(dir / "full/checkpoint.bin", dir / "resumed/checkpoint.bin");
  SolveOptions resumed;
  resumed.output_dir = dir / "resumed";
  resumed.restart = std::filesystem::path();
  ASSERT_EQ(solve_scene(dir / "scene.yaml", resumed), 0);
  const Summary a = Summary::read(dir / "full/summary.yaml"), b = Summary::read(dir / "resumed/summary.yaml");
  double dq = 0;
  for (const char* k : {"D_max", "D_end", "recoil_percent", "max_bending_moment_peak", "max_bending_moment_end", "external_work",
                        "stored_energy_end", "plastic_work_end"})
    dq = std::max(dq, std::abs(qoi(a, k) - qoi(b, k)));
  double du = 0;
  for (const char* arr : {"Displacement", "BendingMoment", "PlasticCurvature", "AccumulatedPlasticCurvature", "Yielding"})
    du = std::max(du, max_difference(frame(dir / "full", 30), frame(dir / "resumed", 30), arr));
  std::printf("ring restart from step 17 of 30: max QoI difference %.2e, max last-frame difference %.2e\n", dq, du);
  EXPECT_LE(dq, 1e-10);
  EXPECT_LE(du, 1e-10);
  EXPECT_GT(qoi(b, "plastic_work_end"), 0.0);
  std::filesystem::remove_all(dir);
}

#endif

}  // namespace stentsim::solver
