#include "pipeline/stage_process.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>

#include "common/error.hpp"
#include "common/log.hpp"
#include "common/summary.hpp"
#include "common/child_process.hpp"

namespace stentsim::pipeline {
namespace {

[[noreturn]] void child_exit(int fd, int code, const std::string& message) {
  if (!message.empty()) {
    std::string m = message.substr(0, 16000);
    [[maybe_unused]] auto w = ::write(fd, m.data(), m.size());
  }
  ::close(fd);
  std::fflush(nullptr);
  ::_exit(code);  // no atexit handlers, no static destructors of the parent's objects
}

}  // namespace

StageChild start_stage(const Stage& stage, const std::filesystem::path& work_dir, const std::filesystem::path& temp_dir,
                       const std::filesystem::path& log_file) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw ComputeError(fmt::format("cannot create a pipe: {}", std::strerror(errno)));
  pid_t pid = -1;
  try {
    // Its own process group (the runner stops the stage and anything it
    // started, mpirun or gmsh, together) and it dies with the runner, so no
    // orphan keeps the work-folder lock: common/child_process.hpp.
    pid = process::spawn([&]() -> int {
      ::close(fds[0]);
      const auto start = std::chrono::steady_clock::now();
      try {
        log::set_file(log_file);
        log::set_prefix(stage.name);
        log::debug("---- stage {} started (pid {}) ----", stage.name, ::getpid());
        StageContext ctx(stage, work_dir, temp_dir);
        stage.run(ctx);
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ctx.summary().set_run(wall, peak_memory_mb_self());
        ctx.summary().write(ctx.output(summary_output(stage.name)));
        log::info("finished in {:.2f} s", wall);
        child_exit(fds[1], 0, "");
      } catch (const InputError& e) {
        // Exit codes as the stand-alone tools' (workflows/cli/main.cpp): 2 a bad input,
        // 1 a computation that failed; collect_stage turns them into the record's kind.
        log::error("{}", e.what());
        child_exit(fds[1], kExitInput, e.what());
      } catch (const std::exception& e) {
        const std::string message = describe_unexpected(e);
        log::error("{}", message);
        child_exit(fds[1], kExitCompute, message);
      } catch (...) {
        log::error("{}", describe_unknown());
        child_exit(fds[1], kExitCompute, describe_unknown());
      }
    });
  } catch (const ComputeError& e) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw ComputeError(fmt::format("cannot start stage '{}': {}", stage.name, e.what()));
  }
  ::close(fds[1]);
  return {pid, fds[0]};
}

StageOutcome collect_stage(const StageChild& child, int wait_status, double peak_memory_mb, double duration_s) {
  StageOutcome o;
  o.duration_s = duration_s;
  o.peak_memory_mb = peak_memory_mb;
  char buf[4096];
  ssize_t n;
  while ((n = ::read(child.message_fd, buf, sizeof buf)) > 0) o.message.append(buf, static_cast<std::size_t>(n));
  ::close(child.message_fd);
  if (WIFEXITED(wait_status)) {
    const int code = WEXITSTATUS(wait_status);
    o.ok = code == 0;
    if (!o.ok) o.error_kind = code == kExitInput ? ErrorKind::input : ErrorKind::compute;
    if (!o.ok && o.message.empty()) o.message = fmt::format("exited with status {}", code);
  } else if (WIFSIGNALED(wait_status)) {
    const int sig = WTERMSIG(wait_status);
    o.interrupted = sig == SIGINT || sig == SIGTERM;
    o.error_kind = o.interrupted ? ErrorKind::interrupted : ErrorKind::crash;
    o.message = fmt::format("killed by signal {} ({})", sig, ::strsignal(sig));
  }
  return o;
}

}  // namespace stentsim::pipeline
