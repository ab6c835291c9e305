// `stentsim cohort`: validation before anything runs, local workers, a second
// run that skips, case selection, expected failures and the summary CSV.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <filesystem>
#include <string>

#include "common/child_process.hpp"
#include "common/files.hpp"
#include "pipeline/manifest.hpp"
#include "tests/workflows/cli_runner.hpp"
#include "workflows/cohort/cohort_plots.hpp"
#include "workflows/cohort/cohort_runner.hpp"
#include "workflows/cohort/cohort_slurm.hpp"

namespace fs = std::filesystem;
using stentsim::files::read_text;
using stentsim::files::write_atomic;

namespace {

using Result = stentsim::testing::CliResult;
Result sh(const std::string& args) { return stentsim::testing::run_stentsim(args); }

// cohort_summary.csv as case id -> column -> cell (every cell is quoted; no newlines in cells).
std::map<std::string, std::map<std::string, std::string>> read_csv(const fs::path& f) {
  std::istringstream in(read_text(f));
  auto fields = [](const std::string& line) {
    std::vector<std::string> out;
    std::string cur;
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
      const char ch = line[i];
      if (quoted && ch == '"' && i + 1 < line.size() && line[i + 1] == '"') cur += '"', ++i;
      else if (ch == '"') quoted = !quoted;
      else if (ch == ',' && !quoted) out.push_back(cur), cur.clear();
      else cur += ch;
    }
    out.push_back(cur);
    return out;
  };
  std::string line;
  std::getline(in, line);
  const auto header = fields(line);
  std::map<std::string, std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    const auto cells = fields(line);
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
    rows[row["case"]] = row;
  }
  return rows;
}

// `cohort status`: stage -> cell of one case's line (fixed-width columns: the
// case in 20 characters, then one space and 18 characters per stage).
std::map<std::string, std::string> status_cells(const std::string& out, const std::string& id) {
  std::istringstream in(out);
  std::string header, line, mine;
  std::getline(in, header);
  while (std::getline(in, line))
    if (line.rfind(id + " ", 0) == 0) mine = line;
  auto trim = [](std::string s) {
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s;
  };
  std::map<std::string, std::string> cells;
  for (std::size_t at = 21; at < header.size(); at += 19) {
    const std::string stage = trim(header.substr(at, 18));
    if (stage.find(' ') != std::string::npos || stage.empty()) break;  // the Slurm columns
    cells[stage] = at < mine.size() ? trim(mine.substr(at, 18)) : "";
  }
  return cells;
}

class Cohort : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("stentsim-cohort-" + std::to_string(::getpid()) + "-" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
    ASSERT_EQ(sh("init " + dir.string() + " --scene generic-artery").code, 0);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string cohort(const std::string& cases) {
    const fs::path f = dir / "cohort.yaml";
    write_atomic(f, "name: t\ntemplate: generic-artery.yaml\nworkers: 2\ncases:\n" + cases);
    return f.string();
  }
  fs::path dir;
};

TEST_F(Cohort, RunsEveryCaseThenSkipsWhatIsUpToDate) {
  const auto f = cohort(
      "  - id: coarse\n    overrides: {mesh: {generic: {elements_around: 16, elements_along: 4}}}\n"
      "  - id: fine\n    overrides: {mesh: {generic: {elements_around: 24, elements_along: 6}}}\n"
      "  - id: other\n    overrides: {mesh: {generic: {elements_around: 20, elements_along: 5}}}\n");
  auto r = sh("cohort run " + f + " --until fibers");  // the solve of a generic artery takes minutes
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("3 cases: 3 as expected, 0 unexpected"), std::string::npos) << r.out;
  const auto csv = read_text(dir / "cohort.work/cohort_summary.csv");
  EXPECT_NE(csv.find("\"case\",\"status\",\"exit_code\",\"failed_stage\",\"error_kind\",\"message\""), std::string::npos) << csv;
  EXPECT_NE(csv.find("\"coarse\",\"done\",\"0\""), std::string::npos) << csv;
  EXPECT_NE(csv.find("mesh.artery_elements"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\"256\""), std::string::npos) << csv;  // 16 x 4 x 4 hex8 for `coarse`
  // One row per case with its inputs: each override as a column of its own.
  auto rows = read_csv(dir / "cohort.work/cohort_summary.csv");
  ASSERT_EQ(rows.size(), 3u) << csv;
  EXPECT_EQ(rows["coarse"]["override.mesh.generic.elements_around"], "16") << csv;
  EXPECT_EQ(rows["fine"]["override.mesh.generic.elements_around"], "24") << csv;
  EXPECT_EQ(rows["other"]["override.mesh.generic.elements_along"], "5") << csv;
  // Override columns are inputs, not QoIs: no plot of them.
  EXPECT_FALSE(fs::exists(dir / "cohort.work/plot_override.mesh.generic.elements_around.png"));
  EXPECT_TRUE(fs::exists(dir / "cohort.work/plot_mesh.artery_elements.png"));
  // Second run: every case's stages are up to date.
  r = sh("cohort run " + f + " --until fibers");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* id : {"coarse", "fine", "other"}) {
    const auto log = read_text(dir / "cohort.work" / id / "run.log");
    EXPECT_NE(log.find("0 ran, 2 up to date"), std::string::npos) << log;  // mesh, fibers
  }
  r = sh("cohort status " + f);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("coarse"), std::string::npos);
  EXPECT_EQ(r.out.find("stale"), std::string::npos) << r.out;
  auto cells = status_cells(r.out, "coarse");
  EXPECT_EQ(cells["mesh"], "done") << r.out;
  EXPECT_EQ(cells["fibers"], "done") << r.out;
  // A changed override makes that case's mesh (and what follows) stale; status
  // says so without rewriting the case file (looking writes nothing).
  const fs::path coarse_case = dir / "cohort.work/coarse/case.yaml";
  const std::string before = read_text(coarse_case);
  const auto mtime = fs::last_write_time(coarse_case);
  write_atomic(f, read_text(f).replace(read_text(f).find("elements_around: 16"), 19, "elements_around: 18"));
  r = sh("cohort status " + f);
  EXPECT_EQ(r.code, 0) << r.out;
  cells = status_cells(r.out, "coarse");
  EXPECT_EQ(cells["mesh"], "stale") << r.out;
  EXPECT_EQ(cells["fibers"], "stale") << r.out;
  EXPECT_EQ(status_cells(r.out, "fine")["mesh"], "done") << r.out;
  EXPECT_EQ(read_text(coarse_case), before);
  EXPECT_EQ(fs::last_write_time(coarse_case), mtime);
}

// `cohort status` before any run creates no work folder.
TEST_F(Cohort, StatusWritesNothing) {
  const auto f = cohort("  - id: a\n  - id: b\n");
  const auto r = sh("cohort status " + f);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("a "), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "cohort.work")) << r.out;
}

// A misspelt stage on the command line stops before anything runs (exit 2,
// "did you mean"), and leaves the cohort summary of the last run as it was.
TEST_F(Cohort, MisspeltStageStopsBeforeAnythingRuns) {
  const auto f = cohort("  - id: a\n  - id: b\n");
  auto r = sh("cohort run " + f + " --cases a --until mesh");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string summary = read_text(dir / "cohort.work/cohort_summary.csv");
  for (const auto& [args, hint] : std::vector<std::pair<std::string, std::string>>{
           {"--until mesj", "--until 'mesj' is not a stage of case 'a'"},
           {"--only fibres", "did you mean 'fibers'?"},
           {"--force mesh_", "--force 'mesh_' is not a stage of case 'a'"},
           {"--cases b --until fibres", "is not a stage of case 'b'"}}) {
    r = sh("cohort run " + f + " " + args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(hint), std::string::npos) << args << "\n" << r.out;
  }
  EXPECT_NE(r.out.find("(its stages: "), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "cohort.work/b/work"));
  EXPECT_FALSE(fs::exists(dir / "cohort.work/a/work/fibers"));
  EXPECT_EQ(read_text(dir / "cohort.work/cohort_summary.csv"), summary);
}

TEST_F(Cohort, SelectsCasesAndPassesRunnerOptions) {
  const auto f = cohort("  - id: a\n  - id: b\n");
  auto r = sh("cohort run " + f + " --cases b --until mesh --workers 1");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_FALSE(fs::exists(dir / "cohort.work/a/work/manifest.yaml"));
  EXPECT_TRUE(fs::exists(dir / "cohort.work/b/work/mesh/artery.vtu"));
  EXPECT_FALSE(fs::exists(dir / "cohort.work/b/work/fibers"));
  // The summary keeps one row per case of the cohort: `a` has not run yet.
  const fs::path csv = dir / "cohort.work/cohort_summary.csv";
  auto rows = read_csv(csv);
  ASSERT_EQ(rows.size(), 2u) << read_text(csv);
  EXPECT_EQ(rows["a"]["status"], "not run") << read_text(csv);
  EXPECT_EQ(rows["b"]["status"], "done") << read_text(csv);
  const std::string b_wall = rows["b"]["wall_time_s"];
  EXPECT_NE(b_wall, "0.000");
  // Running `a` alone keeps `b`'s row from the previous summary, with its QoIs.
  r = sh("cohort run " + f + " --cases a --until mesh --workers 1");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("1 cases: 1 as expected"), std::string::npos) << r.out;  // counts this run's cases only
  rows = read_csv(csv);
  ASSERT_EQ(rows.size(), 2u) << read_text(csv);
  EXPECT_EQ(rows["a"]["status"], "done") << read_text(csv);
  EXPECT_EQ(rows["b"]["status"], "done") << read_text(csv);
  EXPECT_EQ(rows["b"]["wall_time_s"], b_wall) << read_text(csv);
  EXPECT_FALSE(rows["b"]["mesh.artery_elements"].empty()) << read_text(csv);
  EXPECT_NE(read_text(dir / "cohort.work/cohort_summary.md").find("| b | done |"), std::string::npos);
  // Without a previous summary, a left-out case's row comes from its manifest.
  fs::remove(csv);
  r = sh("cohort run " + f + " --cases a --until mesh --workers 1");
  ASSERT_EQ(r.code, 0) << r.out;
  rows = read_csv(csv);
  ASSERT_EQ(rows.size(), 2u) << read_text(csv);
  EXPECT_EQ(rows["b"]["status"], "done") << read_text(csv);
  EXPECT_FALSE(rows["b"]["mesh.artery_elements"].empty()) << read_text(csv);
  r = sh("cohort run " + f + " --cases nope");
  EXPECT_EQ(r.code, 2) << r.out;
}

TEST_F(Cohort, UnexpectedOutcomeExitsOne) {
  // A case declared to fail at `mesh` that succeeds is reported and counted.
  const auto f = cohort("  - id: ok\n  - id: odd\n    expect_failure: mesh\n");
  auto r = sh("cohort run " + f + " --until fibers");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("odd: succeeded unexpectedly"), std::string::npos) << r.out;
  EXPECT_NE(read_text(dir / "cohort.work/cohort_summary.csv").find("\"odd\",\"succeeded unexpectedly\",\"0\""), std::string::npos);
}

TEST_F(Cohort, ExpectedFailureStageNotRunIsDone) {
  // --until stops before the stage meant to fail: nothing unexpected happened.
  const auto f = cohort("  - id: odd\n    expect_failure: fibers\n");
  auto r = sh("cohort run " + f + " --until mesh");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(read_text(dir / "cohort.work/cohort_summary.csv").find("\"odd\",\"done\""), std::string::npos);
  r = sh("cohort run " + f + " --until fibers");  // now fibers runs and succeeds
  EXPECT_EQ(r.code, 1) << r.out;
}

TEST_F(Cohort, BadCohortFilesStopBeforeAnythingRuns) {
  auto r = sh("cohort run " + cohort("  - id: a\n  - id: a\n"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("duplicate case id 'a'"), std::string::npos) << r.out;
  r = sh("cohort run " + cohort("  - id: a\n    overrides: {mesh: {sise: 1 mm}}\n"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("case 'a': mesh.sise: unknown key"), std::string::npos) << r.out;
  r = sh("cohort run " + cohort("  - id: a\n    expect_failure: meshing\n"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("'meshing' is not one of"), std::string::npos) << r.out;
  write_atomic(dir / "missing.yaml", "template: nowhere.yaml\ncases:\n  - id: a\n");
  r = sh("cohort run " + (dir / "missing.yaml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("nowhere.yaml: file not found"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "cohort.work"));
}

// Issue 10: "a case whose input file is missing: a clear error before anything
// runs" -- found by building the case's pipeline plan at load time.
TEST_F(Cohort, MissingInputFileStopsBeforeAnythingRuns) {
  write_atomic(dir / "patient.yaml", "name: p\nscene: patient\ninput: {phantom: {preset: straight-healthy}}\n");
  const fs::path f = dir / "missing.yaml";
  write_atomic(f, "template: patient.yaml\ncases:\n  - id: fine\n"
                  "  - id: gone\n    overrides: {input: {phantom: null, surface: {lumen: scans/p7.stl}}}\n");
  const auto r = sh("cohort run " + f.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(f.string() + ": case 'gone': input.surface.lumen: input file not found: " +
                       (dir / "scans/p7.stl").string()),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(dir / "missing.work"));  // not even the case that is fine ran
  EXPECT_EQ(sh("cohort status " + f.string()).code, 2);
}

// An open tube of radius r along z as an ASCII STL (a lumen with two open ends).
void write_tube_stl(const fs::path& f, double r) {
  const int na = 24, nl = 24;
  const double length = 12.0;
  auto p = [&](int i, int j) {
    const double a = 2 * M_PI * j / na;
    return std::array<double, 3>{r * std::cos(a), r * std::sin(a), length * i / nl};
  };
  std::string s = "solid tube\n";
  for (int i = 0; i < nl; ++i)
    for (int j = 0; j < na; ++j) {
      const auto a = p(i, j), b = p(i, (j + 1) % na), c = p(i + 1, (j + 1) % na), d = p(i + 1, j);
      for (const auto& tri : {std::array<std::array<double, 3>, 3>{a, b, c}, std::array<std::array<double, 3>, 3>{a, c, d}}) {
        s += " facet normal 0 0 0\n  outer loop\n";
        for (const auto& v : tri) s += "   vertex " + std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
        s += "  endloop\n endfacet\n";
      }
    }
  write_atomic(f, s + "endsolid tube\n");
}

// Issue 10: "a folder glob of inputs, e.g. every STL in a folder": one case per
// file, id from the file name, the file put in the given key; duplicates rejected.
TEST_F(Cohort, CasesFromAGlobOfStlFiles) {
  write_atomic(dir / "patient.yaml", "name: p\nscene: patient\ninput: {phantom: {preset: straight-healthy}}\n");
  const double radius[3] = {1.0, 1.25, 1.5};
  const char* names[3] = {"p01", "p02", "p03"};
  for (int i = 0; i < 3; ++i) write_tube_stl(dir / "scans" / (std::string(names[i]) + ".stl"), radius[i]);
  write_atomic(dir / "scans/notes.txt", "not a case\n");
  const fs::path f = dir / "stl.yaml";
  write_atomic(f, "template: patient.yaml\nworkers: 2\ncases:\n  - id: phantom\n"
                  "cases_from:\n  glob: scans/*.stl\n  key: input.surface.lumen\n"
                  "  overrides: {input: {phantom: null, surface: {units: mm}}}\n");
  auto r = sh("cohort run " + f.string() + " --until segmentation");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("4 cases: 4 as expected"), std::string::npos) << r.out;
  // Each case got its own file: the lumen area 2 pi r L (24-gon: x sin(pi/24)/(pi/24)).
  const std::string csv = read_text(dir / "stl.work/cohort_summary.csv");
  for (int i = 0; i < 3; ++i) {
    const std::string merged = read_text(dir / "stl.work" / names[i] / "case.yaml");
    EXPECT_NE(merged.find((dir / "scans" / (std::string(names[i]) + ".stl")).string()), std::string::npos) << merged;
    EXPECT_EQ(merged.find("phantom"), std::string::npos) << merged;  // removed by the null override
    const fs::path summary = dir / "stl.work" / names[i] / "work/segmentation/summary.yaml";
    const std::string s = read_text(summary);
    const double area = 2 * M_PI * radius[i] * 12.0 * std::sin(M_PI / 24) / (M_PI / 24);
    const auto at = s.find("lumen_surface_area");
    ASSERT_NE(at, std::string::npos) << s;
    const auto v = s.find("value:", at);
    EXPECT_NEAR(std::stod(s.substr(v + 6)), area, 1e-3 * area) << names[i];
    EXPECT_NE(csv.find("\"" + std::string(names[i]) + "\",\"done\",\"0\""), std::string::npos) << csv;
  }
  EXPECT_NE(csv.find("\"phantom\",\"done\""), std::string::npos) << csv;
  // The input file of each case, by name, in its override column and its inputs.
  auto rows = read_csv(dir / "stl.work/cohort_summary.csv");
  ASSERT_EQ(rows.size(), 4u) << csv;
  for (int i = 0; i < 3; ++i) {
    const std::string stl = std::string(names[i]) + ".stl";
    EXPECT_EQ(rows[names[i]]["override.input.surface.lumen"], stl) << csv;
    EXPECT_EQ(rows[names[i]]["override.input.surface.units"], "mm") << csv;
    EXPECT_EQ(rows[names[i]]["override.input.phantom"], "null") << csv;
    EXPECT_NE(rows[names[i]]["inputs"].find("surface.lumen=" + stl), std::string::npos) << csv;
  }
  EXPECT_EQ(rows["phantom"]["override.input.surface.lumen"], "") << csv;
  EXPECT_NE(rows["phantom"]["inputs"].find("phantom.preset=straight-healthy"), std::string::npos) << csv;
  // An id that a glob file repeats, and a glob that matches nothing: errors before anything runs.
  write_atomic(f, "template: patient.yaml\ncases:\n  - id: p02\n"
                  "cases_from: [{glob: scans/*.stl, key: input.surface.lumen, overrides: {input: {phantom: null}}}]\n");
  r = sh("cohort run " + f.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("cases_from[0].glob: duplicate case id 'p02' (from " + (dir / "scans/p02.stl").string()), std::string::npos)
      << r.out;
  write_atomic(f, "template: patient.yaml\ncases_from: {glob: scans/*.vtp, key: input.surface.lumen}\n");
  r = sh("cohort run " + f.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("cases_from.glob: 'scans/*.vtp' matches no file"), std::string::npos) << r.out;
  // A wrong key is reported with the case, the key and the file it came from.
  write_atomic(f, "template: patient.yaml\ncases_from: {glob: scans/p01.stl, key: input.surface.lumn, "
                  "overrides: {input: {phantom: null}}}\n");
  r = sh("cohort run " + f.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("case 'p01' (input.surface.lumn from " + (dir / "scans/p01.stl").string() + ")"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("input.surface.lumen: required file path is missing"), std::string::npos) << r.out;
}

// --dry-run with the Slurm back-end prints the array it would submit and
// submits nothing: sbatch here is a fake that leaves a mark if it is called.
TEST_F(Cohort, SlurmDryRunSubmitsNothing) {
  const fs::path bin = dir / "fake-bin";
  for (const char* tool : {"sbatch", "squeue", "scancel", "scontrol"}) {
    write_atomic(bin / tool, "#!/bin/sh\necho \"$0 $*\" >> " + (dir / "called").string() + "\necho 42\n");
    fs::permissions(bin / tool, fs::perms::owner_all);
  }
  const auto f = cohort("  - id: a\n  - id: b\n    overrides: {mesh: {generic: {elements_around: 20}}}\n");
  const std::string env = "PATH=" + bin.string() + ":$PATH ";
  const std::string out = [&] {
    std::string o;
    FILE* p = ::popen((env + STENTSIM_TEST_BINARY + " cohort run " + f + " --backend slurm --dry-run --until mesh 2>&1; echo exit=$?").c_str(), "r");
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) o += buf;
    ::pclose(p);
    return o;
  }();
  EXPECT_NE(out.find("exit=0"), std::string::npos) << out;
  EXPECT_NE(out.find("(dry run, nothing is submitted): 2 cases: 2 to submit"), std::string::npos) << out;
  EXPECT_NE(out.find("'--array=0-1'"), std::string::npos) << out;
  EXPECT_NE(out.find("| cases=( 'a' 'b' )"), std::string::npos) << out;
  EXPECT_NE(out.find("run case.yaml '--until' 'mesh' > run.log"), std::string::npos) << out;  // the real run's arguments
  EXPECT_EQ(out.find("--dry-run' >"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "called")) << read_text(dir / "called");
  EXPECT_FALSE(fs::exists(dir / "cohort.work/cohort_manifest.yaml"));
  EXPECT_FALSE(fs::exists(dir / "cohort.work/slurm"));
  EXPECT_FALSE(fs::exists(dir / "cohort.work/a/work"));
  // A local dry run prints each case's plan and runs nothing either.
  const auto r = sh("cohort run " + f + " --dry-run --until mesh");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("== a =="), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("run   mesh"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "cohort.work/a/work/mesh"));
  EXPECT_FALSE(fs::exists(dir / "cohort.work/cohort_summary.csv"));
}

// ETA from the median stage times so far: each unfinished case needs the
// sampled stages it has not finished, `parallel` at a time.
TEST(CohortEta, MedianStageTimesOverRemainingWork) {
  using stentsim::workflows::cohort_eta;
  EXPECT_FALSE(cohort_eta({}, {{}, {}}, 2));
  const std::map<std::string, std::vector<double>> samples = {{"segmentation", {1, 3, 2}}, {"centerline", {4, 6}}};
  // medians 2 and 5: one case past segmentation (5 left), one not started (7 left), 2 at once.
  EXPECT_DOUBLE_EQ(*cohort_eta(samples, {{"segmentation"}, {}}, 2), 6.0);
  EXPECT_DOUBLE_EQ(*cohort_eta(samples, {{"segmentation", "centerline"}}, 1), 0.0);
  EXPECT_DOUBLE_EQ(*cohort_eta(samples, {{}, {}, {}}, 0), 21.0);  // at least one at a time
}

// A case whose manifest cannot be read fails alone, with the reason, where the
// manifest decides its outcome; what the exit status says alone (a crash, a refused
// case file, an interrupt) stays as it is.
TEST(CohortOutcome, AnUnreadableManifestFailsItsCaseAndNothingElse) {
  using namespace stentsim::workflows;
  const fs::path dir = fs::temp_directory_path() / ("stentsim-cohort-outcome-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "a" / "work");
  const fs::path manifest = dir / "a" / "work" / "manifest.yaml";
  stentsim::files::write_atomic(manifest, "stages: {centerline: [unclosed\n");
  stentsim::files::write_atomic(dir / "a" / "run.log", "error: mesh: the wall is inside the lumen\n");
  CohortConfig c;
  c.work_dir = dir;
  CohortCase k;
  k.id = "a";
  CaseOutcome r;
  ASSERT_NO_THROW(r = case_outcome(c, k, 1, 2.0));
  EXPECT_EQ(r.status, "failed");
  EXPECT_EQ(r.error_kind, "unknown");
  EXPECT_NE(r.manifest_error.find(manifest.string()), std::string::npos) << r.manifest_error;
  EXPECT_NE(r.message.find(manifest.string()), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("the wall is inside the lumen"), std::string::npos) << r.message;
  // Known from the exit status: a killed worker, a case file `stentsim run` refused.
  r = case_outcome(c, k, 128 + 9, 2.0);
  EXPECT_EQ(r.error_kind, "crash");
  EXPECT_NE(r.message.find("killed by signal 9"), std::string::npos) << r.message;
  EXPECT_EQ(case_outcome(c, k, 2, 2.0).error_kind, "input");
  // An interrupted run's manifest is not asked at all.
  r = case_outcome(c, k, 130, 2.0);
  EXPECT_EQ(r.status, "interrupted");
  EXPECT_TRUE(r.manifest_error.empty()) << r.manifest_error;
  // A run that succeeded is asked only when a stage was meant to fail.
  EXPECT_EQ(case_outcome(c, k, 0, 2.0).status, "done");
  k.expect_failure = "placement";
  r = case_outcome(c, k, 0, 2.0);
  EXPECT_EQ(r.status, "failed");
  EXPECT_NE(r.message.find("whether stage placement ran is unknown"), std::string::npos) << r.message;
  // Readable again, with placement failed as the case declares.
  stentsim::pipeline::Manifest m;
  stentsim::pipeline::StageRecord failed;
  failed.status = "failed";
  failed.error_kind = stentsim::pipeline::ErrorKind::input;
  failed.message = "the device does not fit";
  m.set("placement", failed);
  m.save(manifest);
  r = case_outcome(c, k, 1, 2.0);
  EXPECT_EQ(r.status, "failed as expected");
  EXPECT_EQ(r.failed_stage, "placement");
  EXPECT_EQ(r.error_kind, "input");
  EXPECT_TRUE(r.manifest_error.empty()) << r.manifest_error;
  fs::remove_all(dir);
}

TEST(CohortExample, SevereCaseFailsAtPlacementAsExpected) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim-cohort-example-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  auto r = sh("init " + dir.string() + " --cohort");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string f = (dir / "cohort.yaml").string();
  // Two of the six cases, up to placement: one fits, one must fail there.
  r = sh("cohort run " + f + " --cases rca-seed1,severe --until placement");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("severe               failed as expected at placement"), std::string::npos) << r.out;
  const auto csv = read_text(dir / "cohort.work/cohort_summary.csv");
  EXPECT_NE(csv.find("\"severe\",\"failed as expected\",\"1\",\"placement\""), std::string::npos) << csv;
  EXPECT_NE(csv.find("\"rca-seed1\",\"done\""), std::string::npos) << csv;
  EXPECT_NE(csv.find("placement.placement_min_clearance [mm]"), std::string::npos) << csv;
  // One row per case of the cohort (the four not selected have not run), and
  // the expected failure shows as such in `cohort status`.
  EXPECT_EQ(read_csv(dir / "cohort.work/cohort_summary.csv").size(), 6u) << csv;
  // The message is the stage's error, not the log's last lines with their prefixes.
  auto rows = read_csv(dir / "cohort.work/cohort_summary.csv");
  const std::string message = rows["severe"]["message"];
  EXPECT_EQ(message.rfind("stage placement: ", 0), 0u) << message;
  // A device that does not fit the vessel is a bad input (the case's device or site), and
  // the summary says so; the manifest records the same kind.
  EXPECT_EQ(rows["severe"]["error_kind"], "input") << csv;
  EXPECT_EQ(rows["rca-seed1"]["error_kind"], "") << csv;
  EXPECT_NE(read_text(dir / "cohort.work/severe/work/manifest.yaml").find("error_kind: input"), std::string::npos);
  r = sh("cohort status " + f);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(status_cells(r.out, "severe")["placement"], "failed (expected)") << r.out;
  EXPECT_EQ(status_cells(r.out, "severe")["centerline"], "done") << r.out;
  EXPECT_EQ(status_cells(r.out, "rca-seed1")["placement"], "done") << r.out;
  // A PNG per numeric QoI beside the CSV, and the Markdown summary.
  const auto png = read_text(dir / "cohort.work/plot_centerline.stenosis_percent_diameter.png");
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_GT(png.size(), 5000u);
  EXPECT_TRUE(fs::exists(dir / "cohort.work/plot_placement.placement_min_clearance.png"));
  const auto md = read_text(dir / "cohort.work/cohort_summary.md");
  EXPECT_NE(md.find("| severe | failed as expected | placement |"), std::string::npos) << md;
  EXPECT_NE(md.find("(failed as expected at placement, bad input)"), std::string::npos) << md;
  EXPECT_NE(md.find("[plot_centerline.stenosis_percent_diameter.png]"), std::string::npos) << md;
  fs::remove_all(dir);
}

TEST(CohortPlots, OnlyNumericQoisAndFailedCasesMarked) {
  using namespace stentsim::workflows;
  const fs::path dir = fs::temp_directory_path() / ("stentsim-cohort-plots-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  CohortConfig c;
  c.name = "t";
  c.work_dir = dir;
  CohortTable t;
  t.columns = {"case", "status", "failed_stage", "message", "wall_time_s", "mesh.size [mm]", "segmentation.input"};
  t.rows = {{{"case", "a"}, {"status", "done"}, {"mesh.size [mm]", "0.5"}, {"segmentation.input", "phantom"}},
            {{"case", "b"}, {"status", "failed"}, {"failed_stage", "mesh"}, {"message", "boom | x"}},
            {{"case", "c"}, {"status", "failed as expected"}, {"mesh.size [mm]", "0.7"}}};
  EXPECT_EQ(numeric_qoi_columns(t), std::vector<std::string>{"mesh.size [mm]"});
  const auto written = write_cohort_plots(c, t);
  ASSERT_EQ(written.size(), 1u);
  EXPECT_EQ(written[0].filename(), "plot_mesh.size.png");
  EXPECT_GT(fs::file_size(written[0]), 5000u);
  write_cohort_markdown(c, t);
  const auto md = read_text(dir / "cohort_summary.md");
  EXPECT_NE(md.find("| b | failed | mesh |"), std::string::npos) << md;
  EXPECT_NE(md.find("boom \\| x"), std::string::npos) << md;  // '|' escaped in the table
  EXPECT_NE(md.find("| mesh.size | mm | 2 | 0.5 | 0.6 | 0.7 |"), std::string::npos) << md;
  fs::remove_all(dir);
}

// Issue 10: one thread per library inside a cohort. The worker binary here is a
// script that records the environment it was started with: the local pool must
// hand every case OMP_NUM_THREADS=1 and VTK's sequential SMP backend (Debian's
// VTK runs its SMP filters on TBB, which ignores OMP_NUM_THREADS), even when
// the caller's environment says otherwise.
TEST_F(Cohort, LocalWorkersRunWithOneThreadPerLibrary) {
  using namespace stentsim::workflows;
  const fs::path fake = dir / "fake-stentsim";
  write_atomic(fake, "#!/bin/sh\nenv > \"$(dirname \"$2\")/worker.env\"\n");
  fs::permissions(fake, fs::perms::owner_all);
  const auto c = load_cohort(cohort("  - id: a\n  - id: b\n"));
  ::setenv("VTK_SMP_BACKEND_IN_USE", "TBB", 1);
  ::setenv("OMP_NUM_THREADS", "8", 1);
  CohortRunOptions o;
  o.binary = fake.string();
  std::ostringstream out;
  const auto rep = run_cohort(c, o, out);
  ::unsetenv("VTK_SMP_BACKEND_IN_USE");
  ::unsetenv("OMP_NUM_THREADS");
  ASSERT_EQ(rep.cases.size(), 2u) << out.str();
  for (const char* id : {"a", "b"}) {
    const auto env = "\n" + read_text(dir / "cohort.work" / id / "worker.env");
    EXPECT_NE(env.find("\nOMP_NUM_THREADS=1\n"), std::string::npos) << env;
    EXPECT_NE(env.find("\nVTK_SMP_BACKEND_IN_USE=Sequential\n"), std::string::npos) << env;
    EXPECT_EQ(env.find("VTK_SMP_BACKEND_IN_USE=TBB"), std::string::npos) << env;
    EXPECT_NE(env.find("\nVTK_SMP_MAX_THREADS=1\n"), std::string::npos) << env;
    EXPECT_NE(env.find("\nSTENTSIM_THREADS=1\n"), std::string::npos) << env;  // the solver's element loops
    EXPECT_NE(env.find("\nHOME="), std::string::npos) << env;  // the rest of the environment is kept
  }
  const auto single = stentsim::process::single_thread_environment();
  EXPECT_NE(std::find(single.begin(), single.end(), std::make_pair(std::string("VTK_SMP_BACKEND_IN_USE"), std::string("Sequential"))),
            single.end());
}

TEST(CohortSlots, NeverOversubscribeCores) {
  using stentsim::workflows::concurrent_cases;
  EXPECT_EQ(concurrent_cases(4, 1, 2), 2);
  EXPECT_EQ(concurrent_cases(4, 2, 2), 1);
  EXPECT_EQ(concurrent_cases(1, 1, 8), 1);
  EXPECT_EQ(concurrent_cases(8, 4, 2), 1);  // at least one
}

// The Slurm job array's script and sbatch options, from the cohort file (the
// cluster runs are in test_cohort_slurm.cpp).
TEST(CohortSlurmScript, ArrayOptionsAndMpiLauncherFromTheCohortFile) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim-cohort-script-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  ASSERT_EQ(sh("init " + dir.string() + " --cohort").code, 0);
  const fs::path f = dir / "mpi.yaml";
  write_atomic(f, "name: mpi\ntemplate: patient.yaml\nranks_per_case: 2\nbackend: slurm\n"
                  "slurm: {partition: short, time_limit: \"0:30:00\", memory: 4G, extra_sbatch_options: \"--qos=low\"}\n"
                  "cases:\n  - id: a\n  - id: b\n  - id: c\n");
  const auto c = stentsim::workflows::load_cohort(f);
  const auto args = stentsim::workflows::sbatch_array_arguments(c, 3, dir / "logs");
  for (const std::string want : {"--array=0-2", "--ntasks=2", "--partition=short", "--time=0:30:00", "--mem=4G", "--qos=low"})
    EXPECT_NE(std::find(args.begin(), args.end(), want), args.end()) << want;
  EXPECT_NE(std::find(args.begin(), args.end(), "--output=" + (dir / "logs/slurm-%A_%a.out").string()), args.end());
  const std::string s = stentsim::workflows::slurm_array_script(c, {"a", "c"}, "/opt/st sim", {"--until", "centerline"});
  EXPECT_NE(s.find("cases=( 'a' 'c' )"), std::string::npos) << s;
  EXPECT_NE(s.find("'/opt/st sim' run case.yaml '--until' 'centerline' > run.log"), std::string::npos) << s;
  EXPECT_NE(s.find("mpirun --allow-run-as-root --oversubscribe -np ${SLURM_NTASKS:-2}"), std::string::npos) << s;
  EXPECT_NE(s.find("mv -f .exit_code.tmp exit_code"), std::string::npos) << s;
  // One thread per library in every task, exported before the case runs.
  const auto run_at = s.find(" run case.yaml");
  for (const std::string want : {"export OMP_NUM_THREADS='1'\n", "export VTK_SMP_BACKEND_IN_USE='Sequential'\n",
                                 "export VTK_SMP_MAX_THREADS='1'\n"})
    EXPECT_LT(s.find(want), run_at) << want << s;
  // One rank per case: no MPI launcher.
  write_atomic(f, "name: one\ntemplate: patient.yaml\nbackend: slurm\ncases:\n  - id: a\n");
  EXPECT_EQ(stentsim::workflows::slurm_array_script(stentsim::workflows::load_cohort(f), {"a"}, "/x", {}).find("mpirun"),
            std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
