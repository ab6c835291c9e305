// The stability suite's runner (issue 11) classifies what a case's child
// process did: converged, failed cleanly, failed uncleanly, hang, crash, NaN.
// Small shell commands stand in for solver runs so that every class is
// produced on purpose in well under a second (the hang: its short limit).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/summary.hpp"
#include "workflows/study/stability/stability_runner.hpp"

namespace fs = std::filesystem;
using namespace stentsim::study;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("stentsim_stability_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

StabilityCase sh_case(const std::string& id, const std::string& script) {
  StabilityCase c;
  c.id = id;
  c.kind = StabilityCase::Kind::exec;
  c.exec = {"/bin/sh", "-c", script};
  return c;
}

StabilityOutcome run_one(const StabilityCase& c, double limit_s = 30) {
  const fs::path dir = fresh_dir(c.id);
  const ChildRun r = run_child(c.exec, dir, dir / "log.txt", limit_s);
  return classify_case(c, r, dir, dir / "log.txt");
}

std::string read(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST(StabilityRunner, SuccessIsConverged) {
  const auto o = run_one(sh_case("ok", "echo solving; echo done"));
  EXPECT_EQ(o.outcome, "converged");
  EXPECT_EQ(o.run.exit_code, 0);
  EXPECT_EQ(o.run.signal, 0);
  EXPECT_FALSE(o.run.timed_out);
}

// A case is timed on one thread of every library, ours included, whatever this process has set.
TEST(StabilityRunner, ACaseRunsOnOneThreadOfEveryLibrary) {
  ::setenv("STENTSIM_THREADS", "4", 1);
  const fs::path dir = fresh_dir("env");
  const ChildRun r = run_child({"/bin/sh", "-c", "env"}, dir, dir / "log.txt", 30);
  ::unsetenv("STENTSIM_THREADS");
  ASSERT_EQ(r.exit_code, 0);
  const std::string env = "\n" + read(dir / "log.txt");
  for (const char* want : {"\nOMP_NUM_THREADS=1\n", "\nOPENBLAS_NUM_THREADS=1\n", "\nSTENTSIM_THREADS=1\n",
                           "\nVTK_SMP_BACKEND_IN_USE=Sequential\n"})
    EXPECT_NE(env.find(want), std::string::npos) << want << " not in\n" << env;
}

TEST(StabilityRunner, NonzeroExitWithMessageIsCleanFailure) {
  const auto o = run_one(sh_case("clean", "echo step 1; echo 'error: no converged state beyond p = 0.3' >&2; echo bye; exit 1"));
  EXPECT_EQ(o.outcome, "failed cleanly");
  EXPECT_EQ(o.run.exit_code, 1);
  EXPECT_EQ(o.message, "error: no converged state beyond p = 0.3");  // the error line, not the last line
}

TEST(StabilityRunner, SilentNonzeroExitIsUncleanFailure) {
  EXPECT_EQ(run_one(sh_case("silent", "exit 3")).outcome, "failed uncleanly");
  EXPECT_EQ(run_one(sh_case("missing", "exec /nonexistent/solver")).outcome, "failed uncleanly");  // 127
}

TEST(StabilityRunner, SignalIsCrash) {
  const auto o = run_one(sh_case("segv", "echo start; kill -SEGV $$"));
  EXPECT_EQ(o.outcome, "crash");
  EXPECT_EQ(o.run.signal, SIGSEGV);
  EXPECT_NE(o.message.find("signal 11"), std::string::npos) << o.message;
  EXPECT_EQ(run_one(sh_case("abort", "kill -ABRT $$")).outcome, "crash");
}

TEST(StabilityRunner, SleepingChildOverItsLimitIsHang) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto o = run_one(sh_case("sleep", "sleep 30"), 0.5);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(o.outcome, "hang");
  EXPECT_TRUE(o.run.timed_out);
  EXPECT_GE(o.run.wall_s, 0.5);
  EXPECT_LT(took, 5.0);  // ended at the limit, not after 30 s
}

TEST(StabilityRunner, HangIgnoringTermIsKilledWithItsChildren) {
  // The shell ignores SIGTERM and its grandchild too: SIGKILL to the process group 2 s later.
  const fs::path marker = fs::temp_directory_path() / ("stentsim_stability_marker_" + std::to_string(::getpid()));
  fs::remove(marker);
  const auto t0 = std::chrono::steady_clock::now();
  const auto o = run_one(sh_case("stubborn", "trap '' TERM; (trap '' TERM; sleep 4; touch " + marker.string() + ") & sleep 30"), 0.3);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(o.outcome, "hang");
  EXPECT_LT(took, 4.0);
  ::sleep(5);  // the grandchild would have touched the marker by now had it survived
  EXPECT_FALSE(fs::exists(marker)) << "a grandchild of the hung case survived";
  fs::remove(marker);
}

TEST(StabilityRunner, HangEndsGrandchildrenInOtherProcessGroups) {
  // `stentsim run` puts each stage in a process group of its own: a hang must
  // end those too, even when they ignore SIGTERM.
  const fs::path marker = fs::temp_directory_path() / ("stentsim_stability_marker2_" + std::to_string(::getpid()));
  fs::remove(marker);
  const auto o = run_one(sh_case("own_group", "trap '' TERM; setsid sh -c \"trap '' TERM; sleep 4; touch " + marker.string() +
                                                  "\" & sleep 30"),
                         0.3);
  EXPECT_EQ(o.outcome, "hang");
  ::sleep(5);
  EXPECT_FALSE(fs::exists(marker)) << "a grandchild in its own session survived the hang";
  fs::remove(marker);
}

TEST(StabilityRunner, NanInOutputsIsDefectEvenOnSuccess) {
  auto o = run_one(sh_case("nan_summary", "printf 'qoi:\\n  r:\\n    value: .nan\\n    unit: mm\\n' > summary.yaml"));
  EXPECT_EQ(o.outcome, "nan");
  EXPECT_NE(o.message.find("summary.yaml: qoi.r.value"), std::string::npos) << o.message;
  o = run_one(sh_case("nan_csv", "printf 'step,time,r\\n1,0.5,1.2\\n2,1.0,-nan\\n' > history.csv; exit 1"));
  EXPECT_EQ(o.outcome, "nan");
  EXPECT_NE(o.message.find("row 3"), std::string::npos) << o.message;
  // words that start like "inf" are not numbers
  o = run_one(sh_case("words", "printf 'name,note\\ninflation,information\\n' > notes.csv"));
  EXPECT_EQ(o.outcome, "converged");
}

TEST(StabilitySuite, DottedKeysReachListItemsAndRejectWrongPaths) {
  YAML::Node n = YAML::Load("bodies: [{materials: [{neo_hooke: {E: 1, nu: 0.45}}]}]\nsolver: {time: {dt: 0.1}}");
  set_dotted_key(n, "bodies.0.materials.0.neo_hooke.nu", YAML::Node(0.4999));
  set_dotted_key(n, "solver.time.max_cuts", YAML::Node(0));  // a new key in an existing map
  EXPECT_DOUBLE_EQ(n["bodies"][0]["materials"][0]["neo_hooke"]["nu"].as<double>(), 0.4999);
  EXPECT_EQ(n["solver"]["time"]["max_cuts"].as<int>(), 0);
  EXPECT_THROW(set_dotted_key(n, "bodies.1.name", YAML::Node("x")), std::invalid_argument);
  EXPECT_THROW(set_dotted_key(n, "solver.newton.max_iterations", YAML::Node(3)), std::invalid_argument);
  EXPECT_THROW(set_dotted_key(n, "bodies.first.name", YAML::Node("x")), std::invalid_argument);
}

TEST(StabilitySuite, BadSuiteFilesNameFileAndKey) {
  const fs::path dir = fresh_dir("suite_errors");
  auto expect_error = [&](const std::string& text, const std::string& part) {
    stentsim::files::write_atomic(dir / "s.yaml", text);
    try {
      load_stability_suite(dir / "s.yaml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const stentsim::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("s.yaml"), std::string::npos) << e.what();
    }
  };
  expect_error("cases:\n  - {id: a, exec: [true], colour: red}\n", "colour");
  expect_error("cases:\n  - {id: a}\n", "exactly one of scene, case, exec");
  expect_error("cases:\n  - {id: a, scene: nothere.yaml}\n", "does not exist");
  expect_error("cases:\n  - {id: a, exec: [true]}\n  - {id: a, exec: [true]}\n", "used twice");
  expect_error("cases:\n  - {id: a, exec: [true], expect: fine}\n", "expect");
  expect_error("cases:\n  - {id: b, exec: [true], compare: {case: a, qoi: x, tolerance: 1e-8}}\n", "not a case listed before");
  stentsim::files::write_atomic(dir / "scene.yaml", "solver: {time: {dt: 0.1}}\n");
  expect_error("cases:\n  - {id: a, scene: scene.yaml, set: {solver.newton.max_iterations: 3}}\n", "'solver.newton' does not exist");
}

TEST(StabilitySuite, RunWritesTablesAndChecksExpectations) {
  const fs::path dir = fresh_dir("suite_run");
  stentsim::files::write_atomic(dir / "suite.yaml", R"(name: fake
min_limit: 0.5 s
cases:
  - {id: ok, subset: quick, exec: [/bin/sh, -c, "printf 'qoi:\n  tip:\n    value: [1.0, 2.0]\n' > summary.yaml"]}
  - {id: near, subset: quick, exec: [/bin/sh, -c, "printf 'qoi:\n  tip:\n    value: [1.0, 2.000000001]\n' > summary.yaml"],
     compare: {case: ok, qoi: tip, tolerance: 1.0e-8}}
  - {id: far, exec: [/bin/sh, -c, "printf 'qoi:\n  tip:\n    value: [1.0, 2.1]\n' > summary.yaml"],
     compare: {case: ok, qoi: tip, tolerance: 1.0e-8}}
  - {id: stops, subset: quick, exec: [/bin/sh, -c, "echo 'error: no converged state beyond p = 0.2' >&2; exit 1"],
     expect: failed cleanly, message: no converged state beyond}
  - {id: wrong-message, exec: [/bin/sh, -c, "echo 'error: something else' >&2; exit 1"],
     expect: failed cleanly, message: no converged state beyond}
  - {id: hangs, exec: [sleep, "20"], time: 0.01 s}
  - {id: crashes, exec: [/bin/sh, -c, "kill -KILL $$"]}
)");
  const StabilitySuite s = load_stability_suite(dir / "suite.yaml");
  EXPECT_DOUBLE_EQ(s.limit_s(s.cases[5]), 0.5);  // 10 x 0.01 s is below the floor
  std::ostringstream log;
  StabilityOptions o;
  o.out_dir = dir / "out";
  o.subset = "quick";
  const auto quick = run_stability_suite(s, o, log);
  ASSERT_EQ(quick.cases.size(), 3u);
  EXPECT_EQ(quick.unexpected(), 0) << log.str();

  o.subset = "all";
  const auto all = run_stability_suite(s, o, log);
  ASSERT_EQ(all.cases.size(), 7u);
  std::map<std::string, StabilityOutcome> by_id;
  for (const auto& c : all.cases) by_id[c.id] = c;
  EXPECT_TRUE(by_id["near"].as_expected) << by_id["near"].check;
  EXPECT_FALSE(by_id["far"].as_expected);
  EXPECT_NE(by_id["far"].check.find("differs from ok by 0.1"), std::string::npos) << by_id["far"].check;
  EXPECT_TRUE(by_id["stops"].as_expected) << by_id["stops"].check;
  EXPECT_EQ(by_id["wrong-message"].outcome, "failed cleanly");
  EXPECT_FALSE(by_id["wrong-message"].as_expected);
  EXPECT_EQ(by_id["hangs"].outcome, "hang");
  EXPECT_EQ(by_id["crashes"].outcome, "crash");
  EXPECT_EQ(all.unexpected(), 4);

  const std::string csv = read(o.out_dir / "stability.csv"), md = read(o.out_dir / "stability.md");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 8);  // header + 7 rows
  EXPECT_NE(csv.find("hangs,hang,no,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("stops,failed cleanly,yes,"), std::string::npos) << csv;
  EXPECT_NE(md.find("| crashes | crash | **no**"), std::string::npos) << md;
  EXPECT_NE(md.find("3 of 7 case(s) as expected"), std::string::npos) << md;

  // summary.yaml like every other tool: counts per outcome, time and memory.
  const auto sum = stentsim::Summary::read(o.out_dir / "summary.yaml");
  auto q = [&](const std::string& name) {
    const auto it = sum.qois().find(name);
    return it == sum.qois().end() ? -1.0 : std::get<double>(it->second.value);
  };
  EXPECT_EQ(q("cases_total"), 7);
  EXPECT_EQ(q("cases_as_expected"), 3);
  EXPECT_EQ(q("cases_not_as_expected"), 4);
  EXPECT_EQ(q("cases_converged"), 3);  // ok, near, far
  EXPECT_EQ(q("cases_failed_cleanly"), 2);
  EXPECT_EQ(q("cases_hang"), 1);
  EXPECT_EQ(q("cases_crash"), 1);
  EXPECT_EQ(q("cases_nan"), 0);
  EXPECT_GE(q("cases_wall_time_total"), 0.5) << "the hang alone ran to its 0.5 s limit";
  EXPECT_GT(sum.wall_time_s(), 0.0);
  EXPECT_GT(sum.peak_memory_mb(), 0.0);

  o.only = {"stops"};
  EXPECT_EQ(run_stability_suite(s, o, log).cases.size(), 1u);
  o.only = {"nope"};
  EXPECT_THROW(run_stability_suite(s, o, log), stentsim::InputError);
}
