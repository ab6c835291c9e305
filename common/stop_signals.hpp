#pragma once
// The stop signals (SIGINT, SIGTERM) of every loop that runs children: the
// stage runner, the cohort pool, the Slurm follower and the study executor.
// While a StopSignals lives, a stop signal sets a flag instead of ending the
// process, so the loop can pass SIGTERM on to its children and keep what
// they finished. The handlers are installed without SA_RESTART, so a
// blocking call returns EINTR — but a signal that arrives between a check of
// the flag and the blocking call is seen only when the call returns.
//
// Loops that wait for their children therefore use Mode::wait_for_signal: the
// loop reaps with WNOHANG and sleeps in wait(); SIGINT, SIGTERM and SIGCHLD
// stay blocked except inside wait() (ppoll with the signals unblocked), so a
// signal can fall neither between a check of the flag and the sleep nor
// between a fork and the registration of the child. wait() returns after a
// second at the latest (a signal delivered to another thread of the process
// does not wake it). Children started by process::spawn unblock them again.
#include <signal.h>

namespace stentsim::process {

class StopSignals {
 public:
  enum class Mode {
    interrupt_waits,  ///< a stop signal interrupts blocking calls (EINTR)
    wait_for_signal,  ///< signals blocked; wait() sleeps until one (a child's end included) arrives
  };
  /// Installs the handlers; the outermost one clears the flag (a nested one
  /// restores the outer one's handlers when it goes; the flag is shared).
  explicit StopSignals(Mode mode = Mode::interrupt_waits);
  /// Restores the handlers and the signal mask the process had before.
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// The stop signal received since the outermost live StopSignals was made
  /// (0: none); in wait_for_signal mode it first lets a pending stop signal
  /// in. Still readable after it is gone, until the next one is made.
  static int received();
  /// Mode::wait_for_signal only: sleeps until a signal arrives, a second at most.
  void wait() const;

 private:
  Mode mode_;
  sigset_t old_mask_{}, wait_mask_{};
  const sigset_t* outer_wait_mask_ = nullptr;
  struct sigaction old_int_ {}, old_term_ {}, old_chld_ {};
};

}  // namespace stentsim::process
