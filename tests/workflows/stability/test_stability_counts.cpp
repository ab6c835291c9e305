// Newton iterations and step cuts in the stability table count every attempt
// (issue 11). The tube of examples/tube_inflation.yaml (a small mesh) at 1.5x
// its asymptotic pressure stops with "no converged state beyond p = ...": the
// step that stalls (after one or more cut attempts) converges never, so no
// row of history.csv holds its attempts. summary.yaml and stability.csv must still
// count them: step_cuts = the cuts logged ("cutting to dt") + the attempt
// that gave up; newton_iterations = the converged steps' iterations (cut
// attempts included) + at least one per attempt of the stalled step.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/files.hpp"
#include "workflows/study/stability/stability_runner.hpp"

namespace fs = std::filesystem;
using namespace stentsim::study;

namespace {

std::string read(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int count_of(const std::string& text, const std::string& needle) {
  int n = 0;
  for (auto at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

/// Sum of a history.csv column.
double column_sum(const fs::path& csv, const std::string& name) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) header.push_back(c);
  const auto col = std::find(header.begin(), header.end(), name) - header.begin();
  EXPECT_LT(static_cast<std::size_t>(col), header.size()) << name << " not in " << csv;
  double sum = 0;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::string cell;
    for (long i = 0; i <= col && std::getline(ls, cell, ','); ++i) {
    }
    sum += std::stod(cell);
  }
  return sum;
}

}  // namespace

TEST(StabilityCounts, StalledStepAttemptsAreCounted) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_stability_counts_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path tube = fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples" / "tube_inflation.yaml";
  stentsim::files::write_atomic(dir / "suite.yaml", "name: counts\ncases:\n  - id: over\n    scene: " + tube.string() +
                                                        "\n    set: {conditions.0.value: 0.28945538 MPa, "
                                                        "bodies.0.mesh.generate.radial: 2, bodies.0.mesh.generate.circumferential: 6}\n"
                                                        "    expect: failed cleanly\n    message: no converged state beyond p =\n");
  StabilityOptions o;
  o.out_dir = dir / "out";
  o.binary = STENTSIM_TEST_BINARY;
  std::ostringstream progress;
  const StabilityReport r = run_stability_suite(load_stability_suite(dir / "suite.yaml"), o, progress);
  ASSERT_EQ(r.cases.size(), 1u);
  const StabilityOutcome& c = r.cases[0];
  ASSERT_TRUE(c.as_expected) << c.outcome << ": " << c.check << " " << c.message << "\n" << progress.str();

  const fs::path out = o.out_dir / "over" / "out";
  const YAML::Node q = YAML::LoadFile((out / "summary.yaml").string())["qoi"];
  const double newton = q["newton_iterations"]["value"].as<double>(), cuts = q["step_cuts"]["value"].as<double>();
  const double history_newton = column_sum(out / "history.csv", "newton_iterations");
  const double history_cuts = column_sum(out / "history.csv", "step_cuts");
  const int logged_cuts = count_of(read(o.out_dir / "over" / "log.txt"), "cutting to dt");
  ASSERT_GE(logged_cuts, history_cuts);  // the cut attempts of converged steps are logged too
  EXPECT_EQ(cuts, logged_cuts + 1) << "every failed attempt: the logged cuts and the one that gave up";
  const double stalled_attempts = cuts - history_cuts;
  ASSERT_GE(stalled_attempts, 1);
  EXPECT_GE(newton, history_newton + stalled_attempts) << "the stalled step's attempts are missing from newton_iterations";
  // The table reports the summary's totals.
  ASSERT_TRUE(c.iterations && c.cuts);
  EXPECT_EQ(*c.iterations, newton);
  EXPECT_EQ(*c.cuts, cuts);
  std::cout << "steps " << q["steps"]["value"].as<double>() << ", Newton iterations " << newton << " (" << history_newton
            << " in converged steps), cuts " << cuts << " (" << history_cuts << " in converged steps)\n";
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}
