// Runner tests: DAG order, skipping, staleness, failures, interruption,
// the lock and the dry run. Test stages live in test_stages.hpp.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>
#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "common/error.hpp"
#include "common/files.hpp"
#include "pipeline/runner.hpp"
#include "pipeline/work_lock.hpp"
#include "tests/pipeline/test_stages.hpp"

namespace fs = std::filesystem;
using namespace stentsim;
using namespace stentsim::pipeline;
using stentsim::testing::concat_stage;
using stentsim::testing::run_count;

namespace {

class RunnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root = fs::temp_directory_path() / fmt::format("stentsim-runner-{}-{}", ::getpid(),
                                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root);
    fs::create_directories(root);
    work = root / "work";
    counters = root / "counters";
    external = root / "input.txt";
    files::write_atomic(external, "patient data\n");
    config = {{"a", "p=1"}, {"b", "q=1"}, {"c", "r=1"}, {"d", "s=1"}};
  }
  void TearDown() override { fs::remove_all(root); }

  // a <- external; b <- a; c <- b; d <- external (independent of a, b, c).
  // Declared out of order on purpose.
  std::vector<Stage> stages() {
    return {concat_stage("c", {"b/out.txt"}, "c/out.txt", config["c"], counters),
            concat_stage("b", {"a/out.txt"}, "b/out.txt", config["b"], counters),
            concat_stage("a", {external.string()}, "a/out.txt", config["a"], counters),
            concat_stage("d", {external.string()}, "d/out.txt", config["d"], counters)};
  }
  RunReport run(RunOptions o = {}) {
    Runner r(Plan(stages(), work), "test");
    std::ostringstream out;
    auto rep = r.run(o, out);
    last_output = out.str();
    return rep;
  }
  int count(const std::string& s) { return run_count(counters, s); }

  fs::path root, work, counters, external;
  std::map<std::string, std::string> config;
  std::string last_output;
};

TEST_F(RunnerTest, OrdersStagesByTheirDependencies) {
  Plan p(stages(), work);
  std::vector<std::string> names;
  for (auto i : p.order()) names.push_back(p.stages()[i].name);
  auto pos = [&](const std::string& n) { return std::find(names.begin(), names.end(), n) - names.begin(); };
  EXPECT_LT(pos("a"), pos("b"));
  EXPECT_LT(pos("b"), pos("c"));
  auto rep = run();
  EXPECT_EQ(rep.exit_code(), 0);
  EXPECT_EQ(files::read_text(work / "c/out.txt"), "patient data\na:p=1\nb:q=1\nc:r=1\n");
  EXPECT_TRUE(fs::exists(work / "c/summary.yaml"));
  EXPECT_TRUE(fs::exists(work / "manifest.yaml"));
}

TEST_F(RunnerTest, CycleAndMissingProducerAreErrorsAtPlanTime) {
  std::vector<Stage> cyc = {concat_stage("x", {"y/out.txt"}, "x/out.txt", "", counters),
                            concat_stage("y", {"x/out.txt"}, "y/out.txt", "", counters)};
  try {
    Plan p(cyc, work);
    FAIL() << "cycle not detected";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cycle"), std::string::npos) << e.what();
  }
  std::vector<Stage> orphan = {concat_stage("x", {"nobody/out.txt"}, "x/out.txt", "", counters)};
  EXPECT_THROW(Plan(orphan, work), InputError);
  std::vector<Stage> missing_external = {concat_stage("x", {(root / "nope.stl").string()}, "x/out.txt", "", counters)};
  EXPECT_THROW(Plan(missing_external, work), InputError);
}

TEST_F(RunnerTest, SecondRunSkipsEverything) {
  run();
  auto rep = run();
  EXPECT_TRUE(rep.ran.empty());
  EXPECT_EQ(rep.skipped.size(), 4u);
  for (auto s : {"a", "b", "c", "d"}) EXPECT_EQ(count(s), 1) << s;
}

TEST_F(RunnerTest, ParameterChangeRerunsTheStageAndWhatItsOutputFeeds) {
  run();
  config["b"] = "q=2";
  auto rep = run();
  EXPECT_EQ(count("a"), 1);
  EXPECT_EQ(count("b"), 2);
  EXPECT_EQ(count("c"), 2);  // b's output changed
  EXPECT_EQ(count("d"), 1);
  EXPECT_EQ(rep.ran, (std::vector<std::string>{"b", "c"}));
}

TEST_F(RunnerTest, InputChangeRerunsExactlyTheDownstreamStages) {
  run();
  files::write_atomic(external, "patient data, segmented again\n");
  run();
  for (auto s : {"a", "b", "c", "d"}) EXPECT_EQ(count(s), 2) << s;
  // Touching a file without changing its content changes nothing.
  files::write_atomic(external, "patient data, segmented again\n");
  auto rep = run();
  EXPECT_TRUE(rep.ran.empty());
}

TEST_F(RunnerTest, ModifiedOrMissingOutputMakesTheStageStale) {
  run();
  files::write_atomic(work / "b/out.txt", "edited by hand\n");
  run();
  EXPECT_EQ(count("b"), 2);
  EXPECT_EQ(count("c"), 1);  // b's regenerated output equals the recorded one
  fs::remove(work / "a/out.txt");
  run();
  EXPECT_EQ(count("a"), 2);
}

TEST_F(RunnerTest, VersionChangeMakesTheStageStale) {
  run();
  auto st = stages();
  st[2].version = "2";  // stage a
  Runner r(Plan(st, work), "test");
  std::ostringstream out;
  r.run({}, out);
  EXPECT_EQ(count("a"), 2);
  EXPECT_NE(out.str().find("stage version changed"), std::string::npos) << out.str();
}

TEST_F(RunnerTest, FailingStageLeavesEarlierOutputsAndReportsIt) {
  run();
  const std::string before = files::read_text(work / "b/out.txt");
  config["a"] = "p=2";
  config["b"] = "fail";
  auto rep = run();
  EXPECT_EQ(rep.exit_code(), 1);
  EXPECT_EQ(rep.failed, (std::vector<std::string>{"b"}));
  EXPECT_NE(rep.first_failure.find("deliberate failure of b"), std::string::npos);
  // An InputError is a bad input: said on the progress line and recorded as such.
  EXPECT_EQ(rep.first_failure_kind, ErrorKind::input);
  EXPECT_NE(last_output.find("FAIL  b             bad input: deliberate failure of b"), std::string::npos) << last_output;
  EXPECT_EQ(Manifest::load(work / "manifest.yaml").find("b")->error_kind, ErrorKind::input);
  EXPECT_EQ(files::read_text(work / "b/out.txt"), before);  // untouched
  EXPECT_EQ(count("c"), 1);                                  // downstream not run
  EXPECT_FALSE(fs::exists(work / ".tmp" / "b"));
  Runner r(Plan(stages(), work), "test");
  auto st = r.status();
  auto b = std::find_if(st.begin(), st.end(), [](auto& s) { return s.name == "b"; });
  EXPECT_EQ(b->state, StageState::failed);
  // Fixed: the case resumes.
  config["b"] = "q=1";
  EXPECT_EQ(run().exit_code(), 0);
  EXPECT_EQ(count("c"), 2);
}

// --keep-going: after a fails, d (which does not need it) still runs, b and
// c (which do) are reported as not run, and the exit code stays 1.
TEST_F(RunnerTest, KeepGoingRunsWhatDoesNotNeedTheFailedStage) {
  config["a"] = "fail";
  RunOptions o;
  o.keep_going = true;
  auto rep = run(o);
  EXPECT_EQ(rep.exit_code(), 1);
  EXPECT_EQ(rep.failed, (std::vector<std::string>{"a"}));
  EXPECT_EQ(rep.blocked, (std::vector<std::string>{"b", "c"}));
  EXPECT_EQ(count("d"), 1);
  EXPECT_EQ(count("b"), 0);
  EXPECT_EQ(count("c"), 0);
  EXPECT_TRUE(fs::exists(work / "d/out.txt"));
  EXPECT_NE(last_output.find("skip  b             needs a, which failed"), std::string::npos) << last_output;
  // Without it, nothing is launched after the failure (one job: the stages run in plan order).
  fs::remove_all(work);
  fs::remove_all(counters);
  rep = run();
  EXPECT_EQ(rep.exit_code(), 1);
  EXPECT_TRUE(rep.blocked.empty());
  EXPECT_EQ(count("b") + count("c"), 0);
}

TEST_F(RunnerTest, FailedStageKeepsItsPartialOutputsForTheUser) {
  run();
  const std::string before = files::read_text(work / "b/out.txt");
  config["b"] = "q=2 halfway";
  auto rep = run();
  EXPECT_EQ(rep.failed, (std::vector<std::string>{"b"}));
  EXPECT_EQ(rep.first_failure_kind, ErrorKind::compute);  // a ComputeError, its own words passed on
  EXPECT_NE(rep.first_failure.find("deliberate failure of b halfway"), std::string::npos) << rep.first_failure;
  EXPECT_EQ(rep.first_failure.find("internal error"), std::string::npos) << rep.first_failure;
  EXPECT_EQ(Manifest::load(work / "manifest.yaml").find("b")->error_kind, ErrorKind::compute);
  EXPECT_EQ(last_output.find("bad input"), std::string::npos) << last_output;
  EXPECT_EQ(files::read_text(work / "b/out.txt"), before);  // the earlier artifact is untouched
  EXPECT_EQ(files::read_text(work / "failed" / "b" / "b" / "out.txt"), "last converged\n");
  EXPECT_NE(last_output.find("partial outputs: " + (work / "failed" / "b").string()), std::string::npos) << last_output;
  EXPECT_FALSE(fs::exists(work / ".tmp" / "b"));
  // A later run of the stage, failing cleanly or succeeding, removes the old keep.
  config["b"] = "fail";
  run();
  EXPECT_FALSE(fs::exists(work / "failed" / "b"));
  config["b"] = "q=2 halfway";
  run();
  ASSERT_TRUE(fs::exists(work / "failed" / "b"));
  config["b"] = "q=3";
  EXPECT_EQ(run().exit_code(), 0);
  EXPECT_FALSE(fs::exists(work / "failed" / "b"));
}

// What a library or the standard library throws reaches the user worded, never as its bare
// text ("std::bad_alloc", "vector::_M_range_check"), and is a failed computation.
TEST_F(RunnerTest, AStandardExceptionIsWordedNotPrintedRaw) {
  for (const auto& [what, expect] : std::vector<std::pair<std::string, std::string>>{
           {"oom", "out of memory: this input needs more memory"},
           {"bounds", "internal error (please report it with the input that caused it): "},
           {"throw int", "internal error (please report it with the input that caused it): an unknown exception"}}) {
    fs::remove_all(work);
    config["a"] = what;
    auto rep = run();
    EXPECT_EQ(rep.exit_code(), 1) << what;
    EXPECT_NE(rep.first_failure.find(expect), std::string::npos) << what << ": " << rep.first_failure;
    EXPECT_EQ(rep.first_failure.find("std::"), std::string::npos) << rep.first_failure;
    EXPECT_EQ(rep.first_failure_kind, ErrorKind::compute) << what;
    EXPECT_EQ(last_output.find("terminate"), std::string::npos) << last_output;
  }
}

TEST_F(RunnerTest, CrashingStageDoesNotTakeTheRunnerDown) {
  config["d"] = "crash";
  auto rep = run();
  EXPECT_EQ(rep.exit_code(), 1);
  EXPECT_NE(rep.first_failure.find("signal"), std::string::npos) << rep.first_failure;
  EXPECT_EQ(rep.first_failure_kind, ErrorKind::crash);
  EXPECT_EQ(Manifest::load(work / "manifest.yaml").find("d")->error_kind, ErrorKind::crash);
}

TEST(ManifestErrorKind, RoundTripsAndReadsAnOlderRecordAsUnknown) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim-manifest-kind-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Manifest m;
  StageRecord r;
  r.status = "failed";
  r.error_kind = ErrorKind::input;
  m.set("mesh", r);
  r.status = "ok";
  r.error_kind = ErrorKind::none;
  m.set("centerline", r);
  m.save(dir / "manifest.yaml");
  const Manifest back = Manifest::load(dir / "manifest.yaml");
  EXPECT_EQ(back.find("mesh")->error_kind, ErrorKind::input);
  EXPECT_EQ(back.find("centerline")->error_kind, ErrorKind::none);
  files::write_atomic(dir / "old.yaml", "tool_version: x\nstages:\n  mesh: {status: failed, message: boom}\n");
  EXPECT_EQ(Manifest::load(dir / "old.yaml").find("mesh")->error_kind, ErrorKind::unknown);
  for (ErrorKind k : {ErrorKind::input, ErrorKind::compute, ErrorKind::crash, ErrorKind::interrupted})
    EXPECT_EQ(error_kind_from(to_string(k)), k);
  fs::remove_all(dir);
}

TEST_F(RunnerTest, InterruptedRunResumes) {
  run();
  config["a"] = "p=2";
  config["b"] = "sleep";
  const std::string a_before = files::read_text(work / "a/out.txt");
  const std::string b_before = files::read_text(work / "b/out.txt");
  pid_t pid = ::fork();
  if (pid == 0) {
    RunOptions o;
    Runner r(Plan(stages(), work), "test");
    std::ostringstream out;
    auto rep = r.run(o, out);
    ::_exit(rep.exit_code());
  }
  // Wait until b is running (its counter line appears), then interrupt.
  for (int i = 0; i < 300 && count("b") < 2; ++i) ::usleep(20000);
  ASSERT_EQ(count("b"), 2);
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_NE(files::read_text(work / "a/out.txt"), a_before);  // a finished before the stop
  EXPECT_EQ(files::read_text(work / "b/out.txt"), b_before);  // b's old artifact kept
  config["b"] = "q=1";
  auto rep = run();
  EXPECT_EQ(rep.exit_code(), 0);
  EXPECT_EQ(count("a"), 2);  // not re-run
}

TEST_F(RunnerTest, LockStopsASecondRunnerAndStaleLocksAreTakenOver) {
  {
    WorkLock held(work);
    EXPECT_THROW(run(), InputError);
  }
  // A lock file left by a killed runner (no flock held) is stale.
  files::write_atomic(work / ".lock", "pid 999999 on elsewhere since 2026-01-01T00:00:00Z");
  EXPECT_EQ(run().exit_code(), 0);
  EXPECT_NE(last_output.find("stale"), std::string::npos) << last_output;
}

TEST_F(RunnerTest, DryRunExplainsAndRunsNothing) {
  RunOptions o;
  o.dry_run = true;
  run(o);
  EXPECT_NE(last_output.find("run   a"), std::string::npos) << last_output;
  EXPECT_NE(last_output.find("never run"), std::string::npos);
  EXPECT_EQ(count("a"), 0);
  EXPECT_FALSE(fs::exists(work / "manifest.yaml"));
  run();
  config["c"] = "r=9";
  run(o);
  EXPECT_NE(last_output.find("skip  a"), std::string::npos) << last_output;
  EXPECT_NE(last_output.find("configuration changed"), std::string::npos) << last_output;
}

TEST_F(RunnerTest, UntilOnlyAndForceSelectStages) {
  RunOptions until;
  until.until = "b";
  run(until);
  EXPECT_EQ(count("a"), 1);
  EXPECT_EQ(count("b"), 1);
  EXPECT_EQ(count("c"), 0);
  EXPECT_EQ(count("d"), 0);
  RunOptions only;
  only.only = "c";
  run(only);
  EXPECT_EQ(count("c"), 1);
  EXPECT_EQ(count("d"), 0);
  RunOptions force;
  force.force = {"a"};
  run(force);
  EXPECT_EQ(count("a"), 2);
  EXPECT_EQ(count("b"), 1);  // a's output did not change
  RunOptions all;
  all.force_all = true;
  run(all);
  for (auto s : {"b", "c", "d"}) EXPECT_EQ(count(s), 2) << s;
  RunOptions bad;
  bad.only = "nonexistent";
  EXPECT_THROW(run(bad), InputError);
}

TEST_F(RunnerTest, OnlyNeedsItsInputsToExist) {
  RunOptions only;
  only.only = "c";
  EXPECT_THROW(run(only), InputError);
}

TEST_F(RunnerTest, ParallelJobsRunIndependentStagesAtTheSameTime) {
  // a and d are independent; each waits for the other at a barrier, so the
  // run succeeds only if --jobs 2 really runs them concurrently.
  config["a"] = "p=1 barrier";
  config["d"] = "s=1 barrier";
  RunOptions o;
  o.jobs = 2;
  EXPECT_EQ(run(o).exit_code(), 0) << last_output;
  for (auto s : {"a", "b", "c", "d"}) EXPECT_EQ(count(s), 1) << s;
  EXPECT_EQ(files::read_text(work / "c/out.txt"), "patient data\na:p=1 barrier\nb:q=1\nc:r=1\n");
}

TEST_F(RunnerTest, BarrierFailsWithOneJob) {
  // The check above can fail: with one job the barrier is never met.
  config["a"] = "p=1 barrier";
  config["d"] = "s=1 barrier";
  fs::create_directories(counters / "barrier");
  RunOptions o;
  o.jobs = 1;
  o.until = "a";
  EXPECT_EQ(run(o).exit_code(), 1);
}

TEST_F(RunnerTest, StageThatWritesOnlySomeOutputsReplacesNothing) {
  auto two_outputs = [&](const std::string& cfg) {
    auto s = concat_stage("m", {external.string()}, "m/x.txt", cfg, counters);
    s.outputs.push_back("m/y.txt");
    auto inner = s.run;
    s.run = [inner, cfg](StageContext& ctx) {
      inner(ctx);
      if (cfg.find("partial") == std::string::npos) files::write_atomic(ctx.output("m/y.txt"), "y\n");
    };
    return std::vector<Stage>{s};
  };
  {
    Runner r(Plan(two_outputs("v=1"), work), "test");
    std::ostringstream out;
    ASSERT_EQ(r.run({}, out).exit_code(), 0);
  }
  const std::string x_before = files::read_text(work / "m/x.txt");
  Runner r(Plan(two_outputs("v=2 partial"), work), "test");
  std::ostringstream out;
  auto rep = r.run({}, out);
  EXPECT_EQ(rep.exit_code(), 1);
  EXPECT_NE(rep.first_failure.find("did not write its declared output m/y.txt"), std::string::npos) << rep.first_failure;
  EXPECT_EQ(files::read_text(work / "m/x.txt"), x_before);  // not replaced by the partial run
}

TEST_F(RunnerTest, InputEditedWhileTheStageRunsLeavesItStale) {
  // The recorded input hash is the one taken before the stage started.
  auto st = stages();
  auto inner = st[2].run;  // stage a reads `external`
  const auto ext = external;
  st[2].run = [inner, ext](StageContext& ctx) {
    inner(ctx);
    files::write_atomic(ext, "edited during the run\n");
  };
  Runner r(Plan(st, work), "test");
  std::ostringstream out;
  ASSERT_EQ(r.run({}, out).exit_code(), 0);
  EXPECT_EQ(run().ran.front(), "a");  // stale again: its output came from the old content
}

TEST_F(RunnerTest, StageSummaryRecordsTimeAndMemory) {
  run();
  auto s = Summary::read(work / "a/summary.yaml");
  EXPECT_GT(s.peak_memory_mb(), 0.0);
  EXPECT_GE(s.wall_time_s(), 0.0);
  EXPECT_EQ(std::get<double>(s.qois().at("length").value), 19.0);
}

}  // namespace

namespace {

// A stage that counts its attempts in its resume folder and fails while its config says so.
Stage attempt_counter(const std::string& config) {
  Stage s;
  s.name = "r";
  s.outputs = {"r/out.txt"};
  s.config = config;
  s.run = [config](StageContext& ctx) {
    const fs::path counter = ctx.resume_dir() / "attempts";
    const int n = (fs::exists(counter) ? std::stoi(files::read_text(counter)) : 0) + 1;
    files::write_atomic(counter, std::to_string(n));
    if (config == "fail") throw ComputeError("not yet");
    files::write_atomic(ctx.output("r/out.txt"), "attempts " + std::to_string(n) + "\n");
  };
  return s;
}

}  // namespace

// What a stage keeps in its resume folder outlives its failed attempts, goes when the
// stage is forced (from the beginning) and when it has succeeded.
TEST_F(RunnerTest, ResumeFolderOutlivesFailuresAndGoesOnForceAndSuccess) {
  auto run_r = [&](const std::string& config, RunOptions o = {}) {
    Runner r(Plan({attempt_counter(config)}, work), "test");
    std::ostringstream out;
    return r.run(o, out);
  };
  const fs::path counter = work / ".resume/r/attempts";
  EXPECT_EQ(run_r("fail").exit_code(), 1);
  EXPECT_EQ(run_r("fail").exit_code(), 1);
  EXPECT_EQ(files::read_text(counter), "2");
  RunOptions forced;
  forced.force = {"r"};
  EXPECT_EQ(run_r("fail", forced).exit_code(), 1);
  EXPECT_EQ(files::read_text(counter), "1") << "a forced stage starts from the beginning";
  EXPECT_EQ(run_r("ok").exit_code(), 0);
  EXPECT_EQ(files::read_text(work / "r/out.txt"), "attempts 2\n");
  EXPECT_FALSE(fs::exists(work / ".resume")) << "nothing is left to resume after a success";
}
