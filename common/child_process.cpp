#include "common/child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <optional>
#include <thread>

#include "common/error.hpp"
#include "common/log.hpp"

namespace fs = std::filesystem;

namespace stentsim::process {
namespace {

double seconds(const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); }

/// The child's part of spawn(): signals, group, parent link, folder, input,
/// output, environment. Only async-signal-safe calls, except setenv for a
/// setup.env that spawn_exec has not already folded into its envp.
void set_up_child(const ChildSetup& s, pid_t parent, int output_fd, const sigset_t& parent_mask) {
  // The stop signals were blocked across the fork, so none reached the
  // parent's handlers in this process: default actions first, then the
  // parent's mask without them (a parent in StopSignals::Mode::wait_for_signal
  // keeps them blocked outside its waits; the child must not).
  ::signal(SIGINT, SIG_DFL);
  ::signal(SIGTERM, SIG_DFL);
  ::signal(SIGCHLD, SIG_DFL);
  sigset_t mask = parent_mask;
  for (int sig : {SIGINT, SIGTERM, SIGCHLD}) sigdelset(&mask, sig);
  ::pthread_sigmask(SIG_SETMASK, &mask, nullptr);
  ::setpgid(0, 0);
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (::getppid() != parent) ::_exit(1);  // the parent died before prctl took effect
  if (!s.cwd.empty() && ::chdir(s.cwd.c_str()) != 0) ::_exit(126);
  // No terminal input: a child in a background process group of its own that
  // read the terminal would be stopped (SIGTTIN), and its parent wait forever.
  if (const int in = ::open("/dev/null", O_RDONLY); in >= 0) {
    ::dup2(in, 0);
    if (in > 0) ::close(in);
  }
  int fd = output_fd;
  if (fd < 0 && !s.log.empty()) fd = ::open(s.log.c_str(), O_WRONLY | O_CREAT | (s.append_log ? O_APPEND : O_TRUNC), 0644);
  if (fd >= 0) {
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    if (fd > 2) ::close(fd);
  }
  for (const auto& [name, value] : s.env) ::setenv(name.c_str(), value.c_str(), 1);
}

pid_t spawn_with_output(const std::function<int()>& body, const ChildSetup& setup, int output_fd) {
  if (output_fd < 0 && !setup.log.empty() && setup.log.has_parent_path()) fs::create_directories(setup.log.parent_path());
  std::fflush(nullptr);  // nothing buffered is written twice
  const pid_t parent = ::getpid();
  // A stop signal sent to the new child between fork and its reset of the
  // handlers would only set the flag of the parent's handler copy: blocked
  // across the fork, it stays pending in the child until the handlers are the
  // defaults.
  sigset_t stop, old_mask;
  sigemptyset(&stop);
  for (int sig : {SIGINT, SIGTERM, SIGCHLD}) sigaddset(&stop, sig);
  ::pthread_sigmask(SIG_BLOCK, &stop, &old_mask);
  const pid_t pid = ::fork();
  if (pid == 0) {
    set_up_child(setup, parent, output_fd, old_mask);
    int code = 1;
    try {
      code = body();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
    } catch (...) {
      std::fprintf(stderr, "error: unknown exception in a child process\n");
    }
    std::fflush(nullptr);
    ::_exit(code);  // no atexit handlers, no static destructors of the parent's objects
  }
  const int fork_errno = errno;
  if (pid > 0) ::setpgid(pid, pid);  // also here: no race with a stop signal sent right after fork
  ::pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  if (pid < 0) throw ComputeError(fmt::format("cannot start a child process: fork failed: {}", std::strerror(fork_errno)));
  return pid;
}

/// argv and the environment (ours with setup.env applied) as execvpe wants
/// them, built before fork: the child of a multithreaded parent must not
/// allocate (another thread may have held the allocator's lock at the fork).
struct ExecArgs {
  std::vector<std::string> argv_s, env_s;
  std::vector<char*> argv, envp;
  ExecArgs(const std::vector<std::string>& args, const std::vector<std::pair<std::string, std::string>>& env) : argv_s(args) {
    for (char** e = environ; *e; ++e) {
      const std::string kv = *e;
      const std::string key = kv.substr(0, kv.find('='));
      bool replaced = false;
      for (const auto& [k, v] : env) replaced = replaced || k == key;
      if (!replaced) env_s.push_back(kv);
    }
    for (const auto& [k, v] : env) env_s.push_back(k + "=" + v);
    for (auto& s : argv_s) argv.push_back(s.data());
    argv.push_back(nullptr);
    for (auto& s : env_s) envp.push_back(s.data());
    envp.push_back(nullptr);
  }
};

/// The exec body of spawn_exec and run_captured: exit 127 when it cannot execute.
int exec_body(ExecArgs& a) {
  ::execvpe(a.argv[0], a.argv.data(), a.envp.data());
  const char* why = ::strerrordesc_np(errno);  // a static English text: no locale, no allocation
  if (!why) why = "unknown error";
  for (const char* part : {"cannot execute ", static_cast<const char*>(a.argv[0]), ": ", why, "\n"})
    if (::write(2, part, std::strlen(part)) < 0) break;
  ::_exit(127);
}

}  // namespace

pid_t spawn(const std::function<int()>& body, const ChildSetup& setup) { return spawn_with_output(body, setup, -1); }

fs::path self_executable() {
  char buf[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw ComputeError("cannot find the stentsim executable (/proc/self/exe)");
  buf[n] = '\0';
  return fs::path(buf);
}

pid_t spawn_exec(const std::vector<std::string>& argv_s, const ChildSetup& setup) {
  if (argv_s.empty()) throw ComputeError("cannot start a child process: empty command");
  ExecArgs a(argv_s, setup.env);
  ChildSetup without_env = setup;
  without_env.env.clear();  // already in a.envp
  return spawn_with_output([&a]() -> int { return exec_body(a); }, without_env, -1);
}

namespace {
// A child past its time limit (started at `start`) ended with its group and descendants
// (stop_and_reap): its end, timed out. One stuck after SIGKILL reads as killed by it, unreaped.
ChildEnd stop_at_limit(pid_t pid, std::chrono::steady_clock::time_point start, double grace_s) {
  const std::vector<Reaped> ended = stop_and_reap({pid}, grace_s);
  ChildEnd e;
  if (!ended.empty()) e = child_end(ended.front().wait_status, ended.front().usage, 0.0);
  else e.signal = SIGKILL;  // stop_and_reap warned
  e.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  e.timed_out = true;
  return e;
}
}  // namespace

CapturedRun run_captured(const std::vector<std::string>& argv_s, const ChildSetup& setup, double limit_s, double grace_s) {
  if (argv_s.empty()) throw ComputeError("cannot start a child process: empty command");
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw ComputeError(fmt::format("cannot start {}: pipe failed: {}", argv_s[0], std::strerror(errno)));
  ExecArgs a(argv_s, setup.env);
  ChildSetup without_env = setup;
  without_env.env.clear();
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = -1;
  try {
    pid = spawn_with_output([&a]() -> int { return exec_body(a); }, without_env, fds[1]);
  } catch (...) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw;
  }
  ::close(fds[1]);
  CapturedRun r;
  char buf[4096];
  // Read until the command (and whatever inherited its output) closes the pipe, or its
  // time is up: a descendant that keeps the pipe open must not hold the caller either.
  bool hit_limit = false;
  for (;;) {
    int wait_ms = -1;
    if (limit_s > 0.0) {
      const double left = limit_s - std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (left <= 0.0) {
        hit_limit = true;
        break;
      }
      wait_ms = static_cast<int>(std::min(std::ceil(left * 1000.0), 3.6e6));  // poll again at most hourly
    }
    pollfd pf{fds[0], POLLIN, 0};
    const int ready = ::poll(&pf, 1, wait_ms);
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) continue;  // the loop's head decides whether the time is up
    if (ready < 0) break;      // poll failed: the wait below decides
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n > 0) r.output.append(buf, static_cast<std::size_t>(n));
    else if (n < 0 && errno == EINTR) continue;
    else break;
  }
  if (hit_limit) {
    // Ended with its family while the pipe is still open (a command writing into a closed
    // pipe would die of SIGPIPE instead, and read as a failure rather than a timeout).
    // A command that had already exited (a descendant of its held the pipe) keeps its own
    // status; its group goes all the same.
    siginfo_t info{};
    const bool exited = ::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == pid;
    r.end = stop_at_limit(pid, start, grace_s);
    ::close(fds[0]);
    r.end.timed_out = !exited;
    return r;
  }
  ::close(fds[0]);
  // The command closed its output: it has ended or is about to (or it goes on without
  // output, then for the rest of its limit).
  if (limit_s > 0.0) {
    r.end = wait_with_limit(pid, start, limit_s, grace_s);
    return r;
  }
  int status = 0;
  rusage ru{};
  while (::wait4(pid, &status, 0, &ru) < 0)
    if (errno != EINTR) throw ComputeError(fmt::format("waiting for {} failed: {}", argv_s[0], std::strerror(errno)));
  r.end = child_end(status, ru, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return r;
}

std::vector<std::pair<std::string, std::string>> single_thread_environment() {
  return {{"OMP_NUM_THREADS", "1"}, {"OPENBLAS_NUM_THREADS", "1"}, {"VTK_SMP_BACKEND_IN_USE", "Sequential"},
          {"VTK_SMP_MAX_THREADS", "1"}, {"STENTSIM_THREADS", "1"}};
}

std::string ChildEnd::describe() const {
  if (timed_out) return fmt::format("timed out after {:.0f} s", wall_s);
  if (signal) return fmt::format("killed by signal {} ({})", signal, ::strsignal(signal));
  return fmt::format("exit status {}", exit_code);
}

ChildEnd child_end(int wait_status, const rusage& ru, double wall_s) {
  ChildEnd e;
  e.wall_s = wall_s;
  e.cpu_s = seconds(ru.ru_utime) + seconds(ru.ru_stime);
  e.peak_memory_mb = static_cast<double>(ru.ru_maxrss) / 1024.0;  // kB on Linux
  if (WIFEXITED(wait_status)) e.exit_code = WEXITSTATUS(wait_status);
  else if (WIFSIGNALED(wait_status)) e.signal = WTERMSIG(wait_status);
  return e;
}

std::optional<Reaped> poll_any() {
  Reaped r;
  for (;;) {
    r.pid = ::wait4(-1, &r.wait_status, WNOHANG, &r.usage);
    if (r.pid > 0) return r;
    if (r.pid == 0) return std::nullopt;
    if (errno != EINTR) throw ComputeError(fmt::format("waiting for child processes failed: {}", std::strerror(errno)));
  }
}

namespace {
// State and parent of a process from /proc/<pid>/stat (nullopt when it is gone).
struct ProcStat {
  char state = 0;
  pid_t ppid = 0;
};
std::optional<ProcStat> proc_stat(const fs::path& stat_file) {
  std::FILE* f = std::fopen(stat_file.c_str(), "r");
  if (!f) return std::nullopt;
  char buf[512];
  const std::size_t n = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  buf[n] = 0;
  const char* close = std::strrchr(buf, ')');  // the command name may hold spaces
  ProcStat s;
  if (!close || std::sscanf(close + 1, " %c %d", &s.state, &s.ppid) != 2) return std::nullopt;
  return s;
}

// Not gone and not a zombie (an orphan's zombie waits for init).
bool running(pid_t pid) {
  const auto s = proc_stat("/proc/" + std::to_string(pid) + "/stat");
  return s && s->state != 'Z' && s->state != 'X';
}
}  // namespace

std::vector<pid_t> descendants(pid_t root) {
  std::vector<std::pair<pid_t, pid_t>> procs;  // pid, ppid
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    if (const auto s = proc_stat(e.path() / "stat")) procs.emplace_back(std::stoi(name), s->ppid);
  }
  std::vector<pid_t> out{root};
  for (std::size_t i = 0; i < out.size(); ++i)
    for (const auto& [pid, ppid] : procs)
      if (ppid == out[i]) out.push_back(pid);
  out.erase(out.begin());
  return out;
}

void signal_family(pid_t pid, int sig) {
  const auto family = descendants(pid);
  ::kill(-pid, sig);
  for (pid_t d : family) ::kill(d, sig);
}

std::vector<Reaped> stop_and_reap(const std::vector<pid_t>& pids, double grace_s, double stuck_s) {
  // The family as each child leaves it: its group and every descendant, which may sit in
  // groups of their own (a cohort worker's stages) and would otherwise outlive their
  // parent's SIGKILL, holding its work folder's lock.
  std::vector<pid_t> live = pids, family;
  std::vector<Reaped> reaped;
  auto gather = [&] {
    for (pid_t p : live)
      for (pid_t d : descendants(p))
        if (std::find(family.begin(), family.end(), d) == family.end()) family.push_back(d);
  };
  auto signal_all = [&](int sig) {
    for (pid_t p : live) ::kill(-p, sig);
    for (pid_t d : family) ::kill(d, sig);
  };
  gather();
  signal_all(SIGTERM);
  const auto start = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point kill_time;
  bool killed = false;
  for (;;) {
    if (!killed) gather();  // before reaping: a reaped child's descendants are init's
    std::erase_if(live, [&](pid_t p) {
      Reaped r;
      r.pid = ::wait4(p, &r.wait_status, WNOHANG, &r.usage);
      if (r.pid == p) reaped.push_back(r);
      return r.pid == p || (r.pid < 0 && errno == ECHILD);  // reaped, or not ours to wait for
    });
    std::erase_if(family, [](pid_t d) { return !running(d); });
    // Descendants left behind by a child that ended on SIGTERM get the same grace.
    if (live.empty() && (killed || family.empty())) break;
    const auto now = std::chrono::steady_clock::now();
    if (!killed && std::chrono::duration<double>(now - start).count() > grace_s) {
      killed = true;
      kill_time = now;
      signal_all(SIGKILL);
    } else if (killed && std::chrono::duration<double>(now - kill_time).count() > stuck_s) {
      // SIGKILL takes effect when a process leaves the kernel: one in uninterruptible sleep
      // (state D: a hung network file system) can stay there indefinitely, and waiting for
      // it would hang the caller's own way out.
      std::string who;
      for (pid_t p : live) who += fmt::format(" {}", p);
      for (pid_t d : family) who += fmt::format(" {}", d);
      log::warn("processes{} did not end {:.0f} s after SIGKILL (uninterruptible sleep?); going on without them", who, stuck_s);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return reaped;
}

ChildEnd wait_with_limit(pid_t pid, std::chrono::steady_clock::time_point start, double limit_s, double grace_s) {
  Reaped r;
  for (;;) {
    r.pid = ::wait4(pid, &r.wait_status, WNOHANG, &r.usage);
    if (r.pid == pid) break;
    if (r.pid < 0 && errno != EINTR) throw ComputeError(fmt::format("waiting for process {} failed: {}", pid, std::strerror(errno)));
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (elapsed > limit_s) {
      return stop_at_limit(pid, start, grace_s);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(elapsed < 1 ? 5 : 50));
  }
  return child_end(r.wait_status, r.usage, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

namespace {
constexpr int kOutOfMemory = 3;  // the probe child's exit status when the read ran out of its memory budget

// Caps the child's address space at what it maps now plus `budget` bytes, so a damaged
// count fails there (std::bad_alloc) instead of taking the machine's memory. Not under
// AddressSanitizer, whose shadow memory already exceeds any such cap.
void cap_memory(double budget) {
#if !defined(__SANITIZE_ADDRESS__)
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  unsigned long pages = 0;
  if (!f) return;
  const bool ok = std::fscanf(f, "%lu", &pages) == 1;
  std::fclose(f);
  if (!ok) return;
  const double now = static_cast<double>(pages) * static_cast<double>(::sysconf(_SC_PAGESIZE));
  const rlimit cap{static_cast<rlim_t>(now + budget), static_cast<rlim_t>(now + budget)};
  ::setrlimit(RLIMIT_AS, &cap);
#else
  (void)budget;
#endif
}
}  // namespace

void probe_read_in_child(const fs::path& file, const std::string& what, const std::function<void()>& read, double limit_s,
                         double memory_bytes) {
  ChildSetup quiet;
  quiet.log = "/dev/null";
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = spawn(
      [&read, memory_bytes]() -> int {
        cap_memory(memory_bytes);
        try {
          read();
        } catch (const std::bad_alloc&) {
          return kOutOfMemory;
        } catch (...) {
        }
        return 0;
      },
      quiet);
  const ChildEnd end = wait_with_limit(pid, start, limit_s);
  if (end.exit_code == kOutOfMemory)
    throw InputError(fmt::format("{}: the {} reader needs more than {:.0f} MB to read this file (a damaged count?)", file.string(),
                                 what, memory_bytes / 1048576.0));
  if (end.timed_out)
    throw InputError(fmt::format("{}: the {} reader did not finish within {:.0f} s (a damaged file?)", file.string(), what, limit_s));
  // The body returns 0 whatever it read: any other end is a crash (a signal, or the exit
  // status of a handler that caught it, as a sanitizer's).
  if (!end.ok())
    throw InputError(fmt::format("{}: the {} reader crashed on this file ({}): is it damaged or cut short?", file.string(), what,
                                 end.describe()));
}

}  // namespace stentsim::process
