// common/child_process: the one implementation of child processes that the
// stage runner, the cohort pool, the Slurm follower, the error study and the
// stability suite use. Small shell
// commands: working folder, environment, log capture (truncate or append),
// exit status, signal, CPU time and peak memory from wait4, and a function
// body run in a fork.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>

#include "common/error.hpp"
#include "common/child_process.hpp"

namespace fs = std::filesystem;
using namespace stentsim::process;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("stentsim_child_process_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

ChildEnd run(const std::vector<std::string>& argv, const ChildSetup& setup, double limit_s = 30) {
  const auto start = std::chrono::steady_clock::now();
  return wait_with_limit(spawn_exec(argv, setup), start, limit_s);
}

}  // namespace

TEST(PipelineChildProcess, FolderEnvironmentAndLog) {
  const fs::path d = fresh_dir("setup");
  ChildSetup s;
  s.cwd = d;
  s.log = d / "logs" / "run.log";  // its folder is made
  s.env = {{"STENTSIM_CHILD_TEST", "forty-two"}};
  const ChildEnd e = run({"/bin/sh", "-c", "pwd; echo $STENTSIM_CHILD_TEST; echo oops >&2; exit 3"}, s);
  EXPECT_EQ(e.exit_code, 3);
  EXPECT_EQ(e.signal, 0);
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.describe(), "exit status 3");
  EXPECT_EQ(read(s.log), fs::canonical(d).string() + "\nforty-two\noops\n");
  // Truncated by default, appended on request (a study's commands share run.log).
  run({"/bin/sh", "-c", "echo first"}, s);
  s.append_log = true;
  run({"/bin/sh", "-c", "echo second"}, s);
  EXPECT_EQ(read(s.log), "first\nsecond\n");
  fs::remove_all(d);
}

TEST(PipelineChildProcess, ExecFailureSignalAndTiming) {
  const fs::path d = fresh_dir("ends");
  ChildSetup s;
  s.log = d / "log";
  const ChildEnd missing = run({"/nonexistent/tool", "x"}, s);
  EXPECT_EQ(missing.exit_code, 127);
  EXPECT_NE(read(s.log).find("cannot execute /nonexistent/tool"), std::string::npos) << read(s.log);
  const ChildEnd killed = run({"/bin/sh", "-c", "kill -TERM $$"}, s);
  EXPECT_EQ(killed.signal, SIGTERM);
  EXPECT_NE(killed.describe().find("killed by signal 15"), std::string::npos) << killed.describe();
  // A busy loop: CPU time is measured (wait4), close to the wall time it took alone.
  const ChildEnd busy = run({"/bin/sh", "-c", "i=0; while [ $i -lt 200000 ]; do i=$((i+1)); done"}, s);
  EXPECT_TRUE(busy.ok()) << busy.describe();
  EXPECT_GT(busy.cpu_s, 0.02);
  EXPECT_LE(busy.cpu_s, busy.wall_s * 1.05 + 0.01);
  EXPECT_GT(busy.peak_memory_mb, 0.5);
  const ChildEnd slow = run({"sleep", "20"}, s, 0.3);
  EXPECT_TRUE(slow.timed_out);
  EXPECT_LT(slow.wall_s, 5);
  EXPECT_NE(slow.describe().find("timed out"), std::string::npos);
  fs::remove_all(d);
}

namespace {
// Not gone and not a zombie (/proc/<pid>/stat's state).
bool still_running(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), {});
  const auto close = stat.rfind(')');
  return close != std::string::npos && close + 2 < stat.size() && stat[close + 2] != 'Z' && stat[close + 2] != 'X';
}

bool wait_for_file(const fs::path& f) {
  for (int i = 0; i < 500 && !fs::exists(f); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  return fs::exists(f);
}
}  // namespace

// A runner that cannot go on: a child that ignores SIGTERM (a stage stuck in a library)
// is killed after the grace period, and so is the grandchild that a child which ended
// on SIGTERM left behind in a session of its own (a cohort worker's stage); every child
// is reaped.
TEST(PipelineChildProcess, StopAndReapEndsChildrenAndTheirDescendants) {
  const fs::path d = fresh_dir("reap");
  const pid_t stubborn = spawn_exec({"sh", "-c", "trap '' TERM; touch " + (d / "trapped").string() + "; sleep 30"});
  const std::string g = (d / "grandchild").string();
  const pid_t leaver = spawn_exec(
      {"sh", "-c", "setsid sh -c 'trap \"\" TERM; echo $$ > " + g + ".tmp; mv " + g + ".tmp " + g + "; sleep 30' & wait"});
  const pid_t polite = spawn_exec({"sleep", "30"});
  ASSERT_TRUE(wait_for_file(d / "trapped"));
  ASSERT_TRUE(wait_for_file(g));
  const pid_t grandchild = std::stoi(read(g));
  ASSERT_TRUE(still_running(grandchild));
  const auto start = std::chrono::steady_clock::now();
  stentsim::process::stop_and_reap({stubborn, leaver, polite}, 0.5);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(took, 0.5);  // the stubborn ones outlived SIGTERM
  EXPECT_LT(took, 10.0);
  for (const pid_t p : {stubborn, leaver, polite}) {
    errno = 0;
    const pid_t w = ::waitpid(p, nullptr, WNOHANG);
    const int err = errno;
    EXPECT_EQ(w, -1);
    EXPECT_EQ(err, ECHILD);  // already reaped
  }
  bool gone = false;
  for (int i = 0; i < 100 && !gone; ++i, std::this_thread::sleep_for(std::chrono::milliseconds(20))) gone = !still_running(grandchild);
  EXPECT_TRUE(gone) << "the grandchild " << grandchild << " in a session of its own outlived stop_and_reap";
  fs::remove_all(d);
}

TEST(PipelineChildProcess, BodyRunsInItsOwnProcessGroup) {
  const fs::path d = fresh_dir("body");
  ChildSetup s;
  s.log = d / "log";
  const pid_t parent_group = ::getpgrp();
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = spawn(
      [&]() -> int {
        std::printf("group %s\n", ::getpgrp() == ::getpid() && ::getpgrp() != parent_group ? "own" : "shared");
        throw stentsim::ComputeError("body failed");
      },
      s);
  const ChildEnd e = wait_with_limit(pid, start, 30);
  EXPECT_EQ(e.exit_code, 1);  // an exception in the body
  const std::string log = read(s.log);
  EXPECT_NE(log.find("group own"), std::string::npos) << log;
  EXPECT_NE(log.find("error: body failed"), std::string::npos) << log;
  EXPECT_THROW(spawn_exec({}), stentsim::ComputeError);
  fs::remove_all(d);
}

TEST(PipelineChildProcess, EnvironmentOverridesReplaceTheParentsValue) {
  const fs::path d = fresh_dir("env");
  ::setenv("STENTSIM_CHILD_OLD", "parent", 1);
  ChildSetup s;
  s.log = d / "log";
  s.env = {{"STENTSIM_CHILD_OLD", "child"}};
  // sh found through PATH (execvpe), one entry for the variable, the child's value.
  const ChildEnd e = run({"sh", "-c", "env | grep -c '^STENTSIM_CHILD_OLD='; echo $STENTSIM_CHILD_OLD"}, s);
  EXPECT_TRUE(e.ok()) << e.describe();
  EXPECT_EQ(read(s.log), "1\nchild\n");
  ::unsetenv("STENTSIM_CHILD_OLD");
  fs::remove_all(d);
}

TEST(PipelineChildProcess, RunCapturedReturnsBothStreamsAndTheStatus) {
  ChildSetup s;
  s.env = {{"STENTSIM_CHILD_TEST", "seen"}};
  const CapturedRun r = run_captured({"/bin/sh", "-c", "echo out $STENTSIM_CHILD_TEST; echo err >&2; exit 4"}, s);
  EXPECT_EQ(r.end.exit_code, 4);
  EXPECT_EQ(r.output, "out seen\nerr\n");
  const CapturedRun missing = run_captured({"/nonexistent/squeue"});
  EXPECT_EQ(missing.end.exit_code, 127);
  EXPECT_NE(missing.output.find("cannot execute /nonexistent/squeue"), std::string::npos) << missing.output;
  EXPECT_THROW(run_captured({}), stentsim::ComputeError);
}

// A command that does not answer (a hung squeue) is ended at its limit, SIGKILL for one
// that ignores SIGTERM, with what it wrote so far; a descendant that keeps the output
// pipe open after the command exited holds the caller no longer than the limit, and the
// command's own status is kept.
TEST(PipelineChildProcess, RunCapturedEndsACommandAtItsLimit) {
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  const CapturedRun hung = run_captured({"sh", "-c", "trap '' TERM; echo asked; sleep 30"}, {}, 2.0, 0.3);
  double took = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_TRUE(hung.end.timed_out) << hung.end.describe();
  EXPECT_EQ(hung.end.signal, SIGKILL) << hung.end.describe();
  EXPECT_EQ(hung.output, "asked\n");
  EXPECT_GE(took, 2.3);  // the limit, then the grace SIGTERM could not shorten
  EXPECT_LT(took, 10.0);
  t0 = Clock::now();
  const CapturedRun left = run_captured({"sh", "-c", "sleep 30 & echo done; exit 3"}, {}, 1.0);
  took = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_FALSE(left.end.timed_out) << left.end.describe();
  EXPECT_EQ(left.end.exit_code, 3);
  EXPECT_EQ(left.output, "done\n");
  EXPECT_GE(took, 1.0);  // the pipe stayed open until the limit
  EXPECT_LT(took, 10.0);
  const CapturedRun quick = run_captured({"sh", "-c", "echo fast"}, {}, 30.0);
  EXPECT_TRUE(quick.end.ok()) << quick.end.describe();
  EXPECT_EQ(quick.output, "fast\n");
}

// wait_with_limit ends a child at its limit through stop_and_reap, and the child's own end
// (here SIGTERM, which it does not ignore) is what it reports.
TEST(PipelineChildProcess, WaitWithLimitReportsTheSignalThatEndedATimedOutChild) {
  const auto start = std::chrono::steady_clock::now();
  const ChildEnd e = wait_with_limit(spawn_exec({"sleep", "30"}), start, 0.3, 5.0);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(e.timed_out);
  EXPECT_EQ(e.signal, SIGTERM) << e.describe();
  EXPECT_LT(took, 4.0);  // SIGTERM was enough: no wait for the grace
}

TEST(PipelineChildProcess, AChildReadsNoTerminal) {
  // stdin is /dev/null: a read ends at once (a background group reading the
  // terminal would be stopped by SIGTTIN and its parent wait for ever).
  const fs::path d = fresh_dir("stdin");
  ChildSetup s;
  s.log = d / "log";
  // This process's stdin holds a line for the duration: the child must not see it.
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  ASSERT_EQ(::write(fds[1], "line\n", 5), 5);
  ::close(fds[1]);
  const int saved = ::dup(0);
  ::dup2(fds[0], 0);
  ::close(fds[0]);
  const ChildEnd e = run({"/bin/sh", "-c", "if read line; then echo got; else echo eof; fi; ls -l /proc/self/fd/0"}, s, 10);
  ::dup2(saved, 0);
  ::close(saved);
  EXPECT_TRUE(e.ok()) << e.describe();
  EXPECT_NE(read(s.log).find("eof"), std::string::npos) << read(s.log);
  EXPECT_NE(read(s.log).find("/dev/null"), std::string::npos) << read(s.log);
  fs::remove_all(d);
}
