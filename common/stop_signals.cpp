#include "common/stop_signals.hpp"

#include <csignal>
#include <stdexcept>

namespace stentsim::process {
namespace {

volatile std::sig_atomic_t g_received = 0;
extern "C" void on_stop(int sig) { g_received = sig; }
extern "C" void on_child(int) {}  // only ends sigsuspend

}  // namespace

StopSignals::StopSignals(Mode mode) : mode_(mode) {
  g_received = 0;
  if (mode_ == Mode::wait_for_signal) {
    sigset_t block;
    sigemptyset(&block);
    for (int s : {SIGINT, SIGTERM, SIGCHLD}) sigaddset(&block, s);
    sigprocmask(SIG_BLOCK, &block, &old_mask_);
    wait_mask_ = old_mask_;
    for (int s : {SIGINT, SIGTERM, SIGCHLD}) sigdelset(&wait_mask_, s);
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
  if (mode_ == Mode::wait_for_signal) sigprocmask(SIG_SETMASK, &old_mask_, nullptr);
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
  if (mode_ == Mode::wait_for_signal) sigaction(SIGCHLD, &old_chld_, nullptr);
}

int StopSignals::received() { return g_received; }

void StopSignals::wait() const {
  if (mode_ != Mode::wait_for_signal) throw std::logic_error("StopSignals::wait needs Mode::wait_for_signal");
  sigsuspend(&wait_mask_);
}

}  // namespace stentsim::process
