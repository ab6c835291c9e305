#include "workflows/study/stability/child_run.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>

#include "common/error.hpp"

namespace fs = std::filesystem;

namespace stentsim::study {
namespace {

/// Every live descendant of `root` (from the ppid fields of /proc/*/stat). A
/// stage the child started may sit in a process group of its own
/// (pipeline/stage_process.cpp does that), out of reach of kill(-pgid).
std::vector<pid_t> descendants(pid_t root) {
  std::vector<std::pair<pid_t, pid_t>> procs;  // pid, ppid
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::FILE* f = std::fopen((e.path() / "stat").c_str(), "r");
    if (!f) continue;
    char buf[512];
    const std::size_t n = std::fread(buf, 1, sizeof buf - 1, f);
    std::fclose(f);
    buf[n] = 0;
    const char* close = std::strrchr(buf, ')');  // the command name may hold spaces
    int ppid = 0;
    if (close && std::sscanf(close + 1, " %*c %d", &ppid) == 1) procs.emplace_back(std::stoi(name), ppid);
  }
  std::vector<pid_t> out{root};
  for (std::size_t i = 0; i < out.size(); ++i)
    for (const auto& [pid, ppid] : procs)
      if (ppid == out[i]) out.push_back(pid);
  out.erase(out.begin());
  return out;
}

}  // namespace

ChildRun run_child(const std::vector<std::string>& argv_s, const fs::path& cwd, const fs::path& log, double limit_s) {
  if (argv_s.empty()) throw ComputeError("stability: empty command");
  fs::create_directories(cwd);
  if (log.has_parent_path()) fs::create_directories(log.parent_path());
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid < 0) throw ComputeError(fmt::format("stability: fork failed: {}", std::strerror(errno)));
  if (pid == 0) {
    ::setpgid(0, 0);
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    if (::chdir(cwd.c_str()) != 0) ::_exit(126);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      ::close(fd);
    }
    // Cases run one at a time and are timed: one thread per library, so that a
    // case's time does not depend on how many cores the machine lends it.
    ::setenv("OMP_NUM_THREADS", "1", 1);
    std::vector<std::string> copy = argv_s;
    std::vector<char*> argv;
    for (auto& s : copy) argv.push_back(s.data());
    argv.push_back(nullptr);
    ::execvp(argv[0], argv.data());
    std::fprintf(stderr, "stability: cannot run %s: %s\n", argv[0], std::strerror(errno));
    ::_exit(127);
  }
  ::setpgid(pid, pid);  // also here: no race with a kill sent right after fork

  ChildRun r;
  int status = 0;
  rusage ru{};
  bool term_sent = false;
  std::chrono::steady_clock::time_point term_time;
  std::vector<pid_t> family;  // the child's descendants when it was stopped
  for (;;) {
    const pid_t w = ::wait4(pid, &status, WNOHANG, &ru);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) throw ComputeError(fmt::format("stability: wait4 failed: {}", std::strerror(errno)));
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start).count();
    if (!term_sent && elapsed > limit_s) {
      r.timed_out = true;
      family = descendants(pid);
      ::kill(-pid, SIGTERM);
      for (pid_t d : family) ::kill(d, SIGTERM);
      term_sent = true;
      term_time = now;
    } else if (term_sent && std::chrono::duration<double>(now - term_time).count() > 2.0) {
      for (pid_t d : descendants(pid)) family.push_back(d);
      ::kill(-pid, SIGKILL);
      for (pid_t d : family) ::kill(d, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(elapsed < 1 ? 5 : 50));
  }
  // Grandchildren left behind (a stage the child started) go with it.
  if (r.timed_out) {
    ::kill(-pid, SIGKILL);
    for (pid_t d : family) ::kill(d, SIGKILL);
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.cpu_s = static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  r.peak_memory_mb = static_cast<double>(ru.ru_maxrss) / 1024.0;
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  else if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  return r;
}

}  // namespace stentsim::study
