#include "common/stop_signals.hpp"

#include <poll.h>

#include <csignal>
#include <ctime>
#include <initializer_list>
#include <stdexcept>

namespace stentsim::process {
namespace {

volatile std::sig_atomic_t g_received = 0;
int g_depth = 0;  // live StopSignals (nested ones share the flag)
const sigset_t* g_wait_mask = nullptr;  // the live wait_for_signal instance's mask for its waits
extern "C" void on_stop(int sig) { g_received = sig; }
extern "C" void on_child(int) {}  // only ends the wait

}  // namespace

StopSignals::StopSignals(Mode mode) : mode_(mode) {
  if (g_depth++ == 0) g_received = 0;
  if (mode_ == Mode::wait_for_signal) {
    sigset_t block;
    sigemptyset(&block);
    for (int s : {SIGINT, SIGTERM, SIGCHLD}) sigaddset(&block, s);
    pthread_sigmask(SIG_BLOCK, &block, &old_mask_);
    wait_mask_ = old_mask_;
    for (int s : {SIGINT, SIGTERM, SIGCHLD}) sigdelset(&wait_mask_, s);
    outer_wait_mask_ = g_wait_mask;
    g_wait_mask = &wait_mask_;
  }
  struct sigaction sa {};
  sigemptyset(&sa.sa_mask);
  sa.sa_handler = on_stop;
  sa.sa_flags = 0;  // no SA_RESTART
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
  if (mode_ == Mode::wait_for_signal) {
    sa.sa_handler = on_child;
    sa.sa_flags = SA_NOCLDSTOP;
    sigaction(SIGCHLD, &sa, &old_chld_);
  }
}

StopSignals::~StopSignals() {
  // Unblock first, with the handlers still in place: a stop signal that
  // arrived after the last wait sets the flag instead of ending the process.
  if (mode_ == Mode::wait_for_signal) pthread_sigmask(SIG_SETMASK, &old_mask_, nullptr);
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
  if (mode_ == Mode::wait_for_signal) {
    sigaction(SIGCHLD, &old_chld_, nullptr);
    g_wait_mask = outer_wait_mask_;
  }
  --g_depth;
}

int StopSignals::received() {
  // With the signals blocked, a stop sent while the loop was busy is pending:
  // a zero-timeout ppoll with them unblocked runs its handler now, so a loop
  // that checks the flag before starting more work sees it.
  if (g_wait_mask) {
    const timespec zero{0, 0};
    ::ppoll(nullptr, 0, &zero, g_wait_mask);
  }
  return g_received;
}

void StopSignals::wait() const {
  if (mode_ != Mode::wait_for_signal) throw std::logic_error("StopSignals::wait needs Mode::wait_for_signal");
  // ppoll unblocks and sleeps atomically, like sigsuspend, but for a second at
  // most: a signal the kernel gave to another thread of the process (one that
  // does not block it: a library's worker) would not wake this one.
  const timespec second{1, 0};
  ::ppoll(nullptr, 0, &second, &wait_mask_);
}

}  // namespace stentsim::process
