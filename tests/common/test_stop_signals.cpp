// common/stop_signals: the one SIGINT/SIGTERM handler of the loops that run
// children. A stop signal sets the flag and leaves the process alive; the old
// handlers and signal mask come back when it goes; in wait_for_signal mode a
// child's end wakes wait() and a spawned child still receives SIGTERM.
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

bool default_handler(int sig) {
  struct sigaction sa {};
  sigaction(sig, nullptr, &sa);
  return sa.sa_handler == SIG_DFL;
}

}  // namespace

TEST(CommonStopSignals, AStopSignalSetsTheFlagAndTheHandlersComeBack) {
  ASSERT_TRUE(default_handler(SIGINT));
  {
    StopSignals s;
    EXPECT_EQ(StopSignals::received(), 0);
    ::raise(SIGTERM);
    EXPECT_EQ(StopSignals::received(), SIGTERM);
    ::raise(SIGINT);
    EXPECT_EQ(StopSignals::received(), SIGINT);
  }
  EXPECT_EQ(StopSignals::received(), SIGINT);  // still readable after the loop
  EXPECT_TRUE(default_handler(SIGINT));
  EXPECT_TRUE(default_handler(SIGTERM));
  StopSignals again;
  EXPECT_EQ(StopSignals::received(), 0);  // a new one starts clear
  EXPECT_THROW(again.wait(), std::logic_error);
}

TEST(CommonStopSignals, WaitModeBlocksUntilWaitAndAChildStillGetsSigterm) {
  ASSERT_FALSE(blocked(SIGTERM));
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
    // A stop signal raised while blocked is pending until the wait, then sets the flag.
    ::raise(SIGINT);
    EXPECT_EQ(StopSignals::received(), 0);
    s.wait();
    EXPECT_EQ(StopSignals::received(), SIGINT);
  }
  EXPECT_FALSE(blocked(SIGINT));
  EXPECT_FALSE(blocked(SIGCHLD));
  EXPECT_TRUE(default_handler(SIGCHLD));
}
