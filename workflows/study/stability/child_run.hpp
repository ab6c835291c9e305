#pragma once
// Runs one command as a child process under a wall-clock limit, for the
// stability suite (issue 11): the child gets its own process group so that a
// hang is ended with everything it started, its stdout and stderr go to a log
// file, and wait4() gives its exit status and peak memory. The raw facts are
// reported here; stability_runner.hpp turns them into an outcome.
#include <filesystem>
#include <string>
#include <vector>

namespace stentsim::study {

struct ChildRun {
  int exit_code = -1;        ///< exit status when the child exited, else -1
  int signal = 0;            ///< the signal that ended it (0: it exited)
  bool timed_out = false;    ///< still running at the limit: we ended it (a hang)
  double wall_s = 0;         ///< from start to reaped
  double cpu_s = 0;          ///< user + system time of the child
  double peak_memory_mb = 0; ///< max resident set of the child (wait4)
};

/// Runs argv[0] (a path; not looked up in PATH unless it has no '/') with
/// argv in `cwd`, output to `log`. After `limit_s` seconds the child's
/// process group gets SIGTERM, and SIGKILL 2 s later; the run then counts as
/// timed out whatever its status. Throws ComputeError when it cannot start.
ChildRun run_child(const std::vector<std::string>& argv, const std::filesystem::path& cwd,
                   const std::filesystem::path& log, double limit_s);

}  // namespace stentsim::study
