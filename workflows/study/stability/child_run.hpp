#pragma once
// Runs one stability case's command as a child process under a wall-clock
// limit (issue 11): common/child_process.hpp does the work (own process
// group, log capture, wait4 resource usage, SIGTERM then SIGKILL to the
// child and everything it started at the limit). The raw facts are reported
// here; stability_runner.hpp turns them into an outcome.
#include <filesystem>
#include <string>
#include <vector>

#include "common/child_process.hpp"

namespace stentsim::study {

/// exit_code, signal, timed_out, wall_s, cpu_s, peak_memory_mb of a case's run.
using ChildRun = process::ChildEnd;

/// Runs argv[0] (a path; looked up in PATH only when it has no '/') with
/// argv in `cwd`, output to `log` (truncated). After `limit_s` seconds the
/// child's process group and descendants get SIGTERM, and SIGKILL 2 s later;
/// the run then counts as timed out whatever its status. Cases run one at a
/// time and are timed: every library and the assembly on one thread
/// (process::single_thread_environment) so that a case's time does not depend
/// on how many cores the machine lends it. Throws ComputeError when it cannot
/// start.
ChildRun run_child(const std::vector<std::string>& argv, const std::filesystem::path& cwd,
                   const std::filesystem::path& log, double limit_s);

}  // namespace stentsim::study
