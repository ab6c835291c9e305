// The shipped stability suite (examples/studies/stability/stability.yaml,
// issue 11) run through `stentsim study stability`'s own function against the
// stentsim binary: every case must end as the suite expects (converged or
// failed cleanly, never a hang, crash, NaN or an unclean failure). Built
// twice: STABILITY_SUBSET "quick" (CI, a few minutes) and "all" (validation).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "workflows/study/stability/stability_command.hpp"

namespace fs = std::filesystem;

namespace {

// stability.csv cells of one line (quoted cells may hold commas).
std::vector<std::string> csv_cells(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quoted && ch == '"' && i + 1 < line.size() && line[i + 1] == '"') cells.back() += '"', ++i;
    else if (ch == '"') quoted = !quoted;
    else if (ch == ',' && !quoted) cells.emplace_back();
    else cells.back() += ch;
  }
  return cells;
}

}  // namespace

TEST(StabilitySuite, EveryCaseConvergesOrFailsCleanly) {  // or is rejected, where a case expects an input error
  const fs::path suite = fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples" / "studies" / "stability" / "stability.yaml";
  const fs::path out = fs::temp_directory_path() / ("stentsim_stability_suite_" STABILITY_SUBSET "_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const int code = stentsim::study::run_stability_command(
      {suite.string(), "--subset", STABILITY_SUBSET, "--out", out.string(), "--binary", STENTSIM_TEST_BINARY});

  std::ifstream in(out / "stability.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line)) << "no stability.csv";
  const auto header = csv_cells(line);
  auto col = [&](const std::string& name) { return std::find(header.begin(), header.end(), name) - header.begin(); };
  int rows = 0;
  while (std::getline(in, line)) {
    const auto c = csv_cells(line);
    ASSERT_EQ(c.size(), header.size()) << line;
    ++rows;
    const std::string& outcome = c[col("outcome")];
    // "rejected": an input error with its message, for the cases that expect one.
    EXPECT_TRUE(outcome == "converged" || outcome == "failed cleanly" || outcome == "rejected")
        << c[col("case")] << ": " << outcome << ": " << c[col("message")];
    EXPECT_EQ(c[col("as_expected")], "yes") << c[col("case")] << ": " << c[col("check")] << " (" << c[col("message")] << ")";
  }
  EXPECT_GE(rows, 8);
  EXPECT_EQ(code, 0);
  EXPECT_TRUE(fs::exists(out / "stability.md"));
  if (!::testing::Test::HasFailure()) fs::remove_all(out);
}
