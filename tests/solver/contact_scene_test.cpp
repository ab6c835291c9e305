// Contact through scenes (stentsim solve): a stent ring crimped on a balloon
// and expanded by contact alone (examples/contact_ring_on_balloon.yaml); the
// penalty's effect on the ring diameter; the malapposition and lumen-area QoIs
// measured on the ring against the balloon; a ring that starts inside the
// balloon is an input error naming the place.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/summary.hpp"
#include "solver/app/solve.hpp"

namespace stentsim::solver {
namespace {

const std::filesystem::path kExamples = std::filesystem::path(STENTSIM_TEST_SOURCE_DIR) / "examples";

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("stentsim_contact_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

double qoi(const Summary& s, const std::string& key) { return std::get<double>(s.qois().at(key).value); }

/// The ring example with `from` replaced by `to`, written next to the example's data folder.
std::filesystem::path edited(const std::filesystem::path& dir, const std::string& from, const std::string& to) {
  std::string text = files::read_text(kExamples / "contact_ring_on_balloon.yaml");
  if (!from.empty()) {
    const auto at = text.find(from);
    if (at == std::string::npos) throw std::runtime_error("ring example: '" + from + "' not found");
    text.replace(at, from.size(), to);
  }
  // Data paths relative to the example folder.
  for (std::string::size_type at; (at = text.find("file: data/")) != std::string::npos;)
    text.replace(at, 11, "file: " + (kExamples / "data").string() + "/");
  files::write_atomic(dir / "scene.yaml", text);
  return dir / "scene.yaml";
}

Summary run(const std::filesystem::path& scene, const std::filesystem::path& out) {
  SolveOptions o;
  o.output_dir = out;
  EXPECT_EQ(solve_scene(scene, o), 0);
  return Summary::read(out / "summary.yaml");
}

// The malapposition QoI on the ring against the balloon's outer face (the balloon's outward
// normal points away from the ring's axis, as the endothelium's points into the lumen).
const char* kMalapposition =
    "    peak_time: 1\n"
    "  - name: malapposition\n"
    "    type: malapposition\n"
    "    body: stent\n"
    "    solid: balloon\n"
    "    surface: {cell_array: {name: FaceGroup, value: 6}}\n"
    "    times: {max: 1, after: 2}\n"
    "  - name: lumen\n"
    "    type: lumen_area\n"
    "    stent: stent\n"
    "    body: balloon\n"
    "    surface: {cell_array: {name: FaceGroup, value: 6}}\n"
    "    times: {max: 1, after: 2}\n";

TEST(ContactScene, RingIsExpandedByTheBalloonAloneAndPenaltyActsAsExpected) {
  const auto dir = fresh_dir("ring");
  const Summary a = run(edited(dir, "    peak_time: 1\n", kMalapposition), dir / "eps10");
  const double d0 = qoi(a, "D_initial"), dmax = qoi(a, "D_max"), dend = qoi(a, "D_end");
  const double force = qoi(a, "contact_force_stent_balloon_max"), reaction = qoi(a, "max_direction_condition_reaction_peak");
  std::printf("ring on balloon, eps 10: D %.4f -> %.4f (max) -> %.4f mm (after), recoil %.2f %%, contact force %.4g N, "
              "line load max %.4g N/mm, mean penetration %.4g mm, fixation reaction %.3g N\n",
              d0, dmax, dend, qoi(a, "recoil_percent"), force, qoi(a, "contact_line_load_max_stent_balloon_max"),
              qoi(a, "contact_mean_penetration_stent_balloon_max"), reaction);
  EXPECT_NEAR(d0, 1.15, 1e-6);
  EXPECT_GT(dmax, d0 + 0.25);           // expanded, and only contact touches the ring
  EXPECT_LT(dend, dmax);                // springs back after deflation ...
  EXPECT_GT(dend, d0 + 0.05);           // ... held open by its plastic crowns
  EXPECT_GT(force, 0.0);
  EXPECT_LT(reaction, 1e-2 * force);    // the fixations only keep the ring from drifting
  EXPECT_EQ(qoi(a, "contact_active_points_stent_balloon_after"), 0.0);  // the deflated balloon has let go
  // Neither the struts (no beam–beam contact) nor the balloon's surface (no self-contact) overlap.
  EXPECT_EQ(qoi(a, "strut_overlap_points_max_stent"), 0.0);
  EXPECT_EQ(qoi(a, "self_intersection_pairs_max_balloon"), 0.0);
  EXPECT_EQ(qoi(a, "self_intersection_first_time_balloon"), -1.0);

  // Malapposition. Initially every strut is 0.025 mm from the balloon's round surface, up to
  // 0.49 (1 - cos(pi / 29)) = 0.0029 mm more over the middle of its 29 chord faces.
  std::printf("malapposition: max gap %.4f / %.4f / %.4f mm, mean %.4f / %.4f / %.4f mm, not in contact %.3f / %.3f / %.3f, "
              "malapposed %.3f (after)\n",
              qoi(a, "malapposition_max_gap_initial"), qoi(a, "malapposition_max_gap_max"), qoi(a, "malapposition_max_gap_after"),
              qoi(a, "malapposition_mean_gap_initial"), qoi(a, "malapposition_mean_gap_max"), qoi(a, "malapposition_mean_gap_after"),
              qoi(a, "not_in_contact_fraction_initial"), qoi(a, "not_in_contact_fraction_max"), qoi(a, "not_in_contact_fraction_after"),
              qoi(a, "malapposed_fraction_after"));
  EXPECT_GT(qoi(a, "malapposition_mean_gap_initial"), 0.025 - 1e-4);
  EXPECT_LT(qoi(a, "malapposition_max_gap_initial"), 0.025 + 0.0029 + 1e-4);
  EXPECT_EQ(qoi(a, "not_in_contact_fraction_initial"), 1.0);
  EXPECT_EQ(qoi(a, "malapposed_fraction_initial"), 0.0);
  EXPECT_DOUBLE_EQ(qoi(a, "malapposition_threshold"), 0.12);  // 2 R
  // At max pressure the balloon presses on the whole ring (penalty contact: small negative gaps).
  EXPECT_LT(qoi(a, "not_in_contact_fraction_max"), 0.05);
  EXPECT_LT(qoi(a, "malapposition_max_gap_max"), 0.005);
  // After deflation the ring stays open over the balloon, which is back near its 0.49 mm radius:
  // the mean gap is the ring's radius less the balloon's and the strut radius.
  EXPECT_NEAR(qoi(a, "malapposition_mean_gap_after"), 0.5 * dend - 0.49 - 0.06, 0.01);
  EXPECT_EQ(qoi(a, "not_in_contact_fraction_after"), 1.0);

  // Lumen area, here the balloon's cross-section in the ring's plane: initially the 29-gon of
  // circumradius 0.49 mm, 29/2 0.49^2 sin(2 pi/29) = 0.7483 mm^2; at max pressure the circle
  // inside the ring's struts, the 29-gon of circumradius D_max/2 - R + mean penetration (D_max
  // at the crowns; the plane through the ring's centroid also cuts the balloon between struts).
  auto polygon29 = [](double r) { return 14.5 * r * r * std::sin(2 * M_PI / 29); };
  const double a0 = polygon29(0.49);
  const double a_max = polygon29(0.5 * dmax - 0.06 + qoi(a, "contact_mean_penetration_stent_balloon_max"));
  std::printf("lumen area: %.4f (initial, 29-gon %.4f), %.4f (max, inside the ring %.4f), %.4f mm^2 (after)\n",
              qoi(a, "lumen_area_min_initial"), a0, qoi(a, "lumen_area_min_max"), a_max, qoi(a, "lumen_area_min_after"));
  EXPECT_EQ(qoi(a, "lumen_area_stations"), 1.0);  // one ring: one plane
  EXPECT_EQ(qoi(a, "lumen_area_open_stations_max"), 0.0);
  EXPECT_NEAR(qoi(a, "lumen_area_min_initial"), a0, 2e-3 * a0);
  EXPECT_NEAR(qoi(a, "lumen_area_min_max"), a_max, 0.02 * a_max);
  EXPECT_NEAR(qoi(a, "lumen_area_min_after"), a0, 0.05 * a0);

  // Between ε and 10ε the balloon's outer diameter stays nearly the same, so the ring's diameter
  // grows by twice the penetration it loses: ΔD ≈ 2 Δ(mean penetration), within 10 %.
  const Summary b = run(edited(dir, "penalty: 10 N/mm^2", "penalty: 100 N/mm^2"), dir / "eps100");
  const double dd = qoi(b, "D_max") - dmax;
  const double dp = qoi(a, "contact_mean_penetration_stent_balloon_max") - qoi(b, "contact_mean_penetration_stent_balloon_max");
  std::printf("eps 10 -> 100: D_max %.6f -> %.6f mm (dD %.4g), mean penetration %.4g -> %.4g mm (2 dp %.4g)\n", dmax,
              qoi(b, "D_max"), dd, qoi(a, "contact_mean_penetration_stent_balloon_max"),
              qoi(b, "contact_mean_penetration_stent_balloon_max"), 2 * dp);
  EXPECT_GT(dp, 0.0);
  EXPECT_NEAR(dd, 2 * dp, 0.1 * 2 * dp);
  std::filesystem::remove_all(dir);
}

TEST(ContactScene, ARingStartingInsideTheBalloonIsAnInputErrorNamingThePlace) {
  const auto dir = fresh_dir("inside");
  // A strut radius of 0.1 mm puts the crimped ring about 0.015 mm inside the balloon (a little less: the faces are chords).
  const auto scene = edited(dir, "penalty: 10 N/mm^2", "penalty: 10 N/mm^2\n    radius: 0.1 mm");
  SolveOptions o;
  o.output_dir = dir / "out";
  try {
    solve_scene(scene, o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("contact 'stent_balloon'"), std::string::npos) << m;
    EXPECT_NE(m.find("starts inside"), std::string::npos) << m;
    EXPECT_NE(m.find("of element"), std::string::npos) << m;
    EXPECT_NE(m.find("has gap -0.01"), std::string::npos) << m;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace stentsim::solver
