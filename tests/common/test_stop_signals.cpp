// common/stop_signals: the one SIGINT/SIGTERM handler of the loops that run
// children. A stop signal sets the flag and leaves the process alive; the old
// handlers and signal mask come back when it goes; a nested one keeps the
// outer one's stop; in wait_for_signal mode a child's end wakes wait() and a
// spawned child still receives SIGTERM.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>

#include "common/child_process.hpp"
#include "common/stop_signals.hpp"

using namespace stentsim::process;

namespace {

bool blocked(int sig) {
  sigset_t now;
  sigprocmask(SIG_BLOCK, nullptr, &now);
  return sigismember(&now, sig) == 1;
}

void (*handler_of(int sig))(int) {
  struct sigaction sa {};
  sigaction(sig, nullptr, &sa);
  return sa.sa_handler;
}

}  // namespace

TEST(CommonStopSignals, AStopSignalSetsTheFlagAndTheHandlersComeBack) {
  // What the test started with (a background job of a shell may start with SIGINT ignored).
  const auto int_before = handler_of(SIGINT), term_before = handler_of(SIGTERM);
  {
    StopSignals s;
    EXPECT_EQ(StopSignals::received(), 0);
    ::raise(SIGTERM);
    EXPECT_EQ(StopSignals::received(), SIGTERM);
    ::raise(SIGINT);
    EXPECT_EQ(StopSignals::received(), SIGINT);
  }
  EXPECT_EQ(StopSignals::received(), SIGINT);  // still readable after the loop
  EXPECT_EQ(handler_of(SIGINT), int_before);
  EXPECT_EQ(handler_of(SIGTERM), term_before);
  StopSignals again;
  EXPECT_EQ(StopSignals::received(), 0);  // a new one starts clear
  ::raise(SIGTERM);
  {
    StopSignals nested;  // shares the flag: does not clear the outer one's stop
    EXPECT_EQ(StopSignals::received(), SIGTERM);
  }
  EXPECT_THROW(again.wait(), std::logic_error);
}

TEST(CommonStopSignals, WaitModeBlocksUntilWaitAndAChildStillGetsSigterm) {
  const bool int_blocked = blocked(SIGINT), chld_blocked = blocked(SIGCHLD);
  const auto chld_before = handler_of(SIGCHLD);
  {
    StopSignals s(StopSignals::Mode::wait_for_signal);
    EXPECT_TRUE(blocked(SIGINT));
    EXPECT_TRUE(blocked(SIGTERM));
    EXPECT_TRUE(blocked(SIGCHLD));
    // A child started with the signals blocked here has them deliverable.
    const pid_t pid = spawn_exec({"sleep", "30"});
    const auto start = std::chrono::steady_clock::now();
    ::usleep(100000);
    ::kill(-pid, SIGTERM);
    int status = 0;
    while (::waitpid(pid, &status, WNOHANG) == 0) s.wait();  // its SIGCHLD wakes the wait
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10);
    // A stop signal raised while the loop is busy (blocked) is seen by its next check of
    // the flag, before it starts more work, not only after the next wait.
    ::raise(SIGINT);
    EXPECT_EQ(StopSignals::received(), SIGINT);
  }
  EXPECT_EQ(blocked(SIGINT), int_blocked);
  EXPECT_EQ(blocked(SIGCHLD), chld_blocked);
  EXPECT_EQ(handler_of(SIGCHLD), chld_before);
}
