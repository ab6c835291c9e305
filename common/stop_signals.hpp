#pragma once
// The stop signals (SIGINT, SIGTERM) of every loop that runs children: the
// stage runner, the cohort pool, the Slurm follower and the study executor.
// While a StopSignals lives, a stop signal sets a flag instead of ending the
// process, so the loop can pass SIGTERM on to its children and keep what
// they finished. The handlers are installed without SA_RESTART: a blocking
// wait4() returns EINTR and the loop sees the flag at once.
//
// With Mode::wait_for_signal the loop sleeps in wait() instead of a blocking
// wait: SIGINT, SIGTERM and SIGCHLD stay blocked except inside wait()
// (sigsuspend), so a signal can fall neither between a check of the flag and
// the sleep nor between a fork and the registration of the child. Children
// started by process::spawn unblock them again.
#include <signal.h>

namespace stentsim::process {

class StopSignals {
 public:
  enum class Mode {
    interrupt_waits,  ///< a stop signal interrupts blocking calls (EINTR)
    wait_for_signal,  ///< signals blocked; wait() sleeps until one (a child's end included) arrives
  };
  /// Clears the flag and installs the handlers (a nested one restores the
  /// outer one's handlers when it goes; the flag is shared).
  explicit StopSignals(Mode mode = Mode::interrupt_waits);
  /// Restores the handlers and the signal mask the process had before.
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// The stop signal received since the last StopSignals was made (0: none).
  /// Still readable after it is gone, until the next one is made.
  static int received();
  /// Mode::wait_for_signal only: sleeps until a signal arrives.
  void wait() const;

 private:
  Mode mode_;
  sigset_t old_mask_{}, wait_mask_{};
  struct sigaction old_int_ {}, old_term_ {}, old_chld_ {};
};

}  // namespace stentsim::process
