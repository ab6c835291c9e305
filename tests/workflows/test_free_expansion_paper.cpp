// The paper's straight free expansion (Section 3.1; validation/targets.yaml
// free_expansion_straight) through `stentsim run` on the bundled example, at
// both readings of the paper's "13 atm or 1.01 MPa" (DESIGN.md §8: run 1.01 MPa,
// report 1.317 MPa too).
//
// At 13 atm (1.317 MPa) the stent's diameters and recoil are judged against the
// paper's: that is the reading its own numbers support. Its dogboning peak sits
// "at 10.4 atm", which a ramp to 1.01 MPa (9.97 atm) never reaches and which is
// 0.8 × 13 atm. At 1.01 MPa the stent stops short (about 2.27 mm against 2.59):
// the balloon alone climbs its steep knee there (outer diameter 2.21 mm at
// 0.6 MPa, 2.52 mm at 0.7 MPa; test_solver_balloon_inflation) and the stent's
// resistance is nearly flat (an equivalent 0.36 MPa at 2.26 mm, 0.40 MPa at
// 2.58 mm, from the external work of one ring expanded by its crowns), so the
// diameter reached at p_max turns on a few hundredths of an MPa. Those numbers
// are printed, not judged.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>

#include "common/files.hpp"
#include "tests/workflows/cli_runner.hpp"
#include "tests/workflows/summary_qoi.hpp"

namespace fs = std::filesystem;
using stentsim::testing::run_stentsim;
using stentsim::testing::summary_qoi;

namespace {

struct Expansion {
  double d_max, d_after, recoil, dogboning, dogboning_pressure;
};

/// The bundled example with `pressure_max` replaced, run end to end in `dir`.
Expansion run_example(const fs::path& dir, const std::string& pressure) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string example = stentsim::files::read_text(fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples/free-expansion.yaml");
  const std::string text = std::regex_replace(example, std::regex("pressure_max: [^#\\n]*"), "pressure_max: " + pressure + " ");
  EXPECT_NE(text, example) << "the example names no pressure_max";
  stentsim::files::write_atomic(dir / "free-expansion.yaml", text);
  const auto r = run_stentsim("run " + (dir / "free-expansion.yaml").string());
  EXPECT_EQ(r.code, 0) << r.out;
  const fs::path sum = dir / "free-expansion.work/solve/summary.yaml";
  Expansion e{summary_qoi(sum, "stent_diameter_max"), summary_qoi(sum, "stent_diameter_after"), summary_qoi(sum, "recoil_percent"),
              summary_qoi(sum, "dogboning_percent"), summary_qoi(sum, "dogboning_pressure")};
  std::printf("p_max %s: stent D %.4f mm at max (paper 2.59), %.4f mm after (paper 2.31), recoil %.2f %% (paper 10.8), "
              "dogboning %.1f %% at %.3f MPa (paper 20.4 %% at 10.4 atm = 1.054 MPa)\n",
              pressure.c_str(), e.d_max, e.d_after, e.recoil, e.dogboning, e.dogboning_pressure);
  return e;
}

TEST(FreeExpansionPaper, At13AtmTheStentReachesThePapersDiametersAndRecoil) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim-fe-paper-" + std::to_string(::getpid()));
  const Expansion e = run_example(dir / "13atm", "13 atm");
  EXPECT_NEAR(e.d_max, 2.59, 0.03 * 2.59);    // targets.yaml tolerance 3 %
  EXPECT_NEAR(e.d_after, 2.31, 0.03 * 2.31);
  EXPECT_NEAR(e.recoil, 10.8, 2.0);
  const Expansion low = run_example(dir / "1.01MPa", "1.01 MPa");
  EXPECT_LT(low.d_max, e.d_max);
  fs::remove_all(dir);
}

}  // namespace
