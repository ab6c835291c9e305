#pragma once
// Runs one stage in a child process (fork, common/child_process.hpp): a
// crash, an abort or a memory blow-up in a stage cannot take the runner
// down, and wait4() gives the stage's peak memory. The child writes outputs
// under temporary names only; a failure's message comes back through a pipe.
#include <sys/types.h>

#include <string>

#include "pipeline/manifest.hpp"
#include "pipeline/stage.hpp"

namespace stentsim::pipeline {

struct StageChild {
  pid_t pid = -1;
  int message_fd = -1;  // read end of the pipe carrying a failure message
};

/// A stage child's exit codes, as the stand-alone tools' (0 is success).
inline constexpr int kExitCompute = 1;
inline constexpr int kExitInput = 2;

struct StageOutcome {
  bool ok = false;
  bool interrupted = false;  // ended by SIGINT/SIGTERM
  ErrorKind error_kind = ErrorKind::none;
  std::string message;       // failure message
  double duration_s = 0;
  double peak_memory_mb = 0;
};

/// Forks a child that runs `stage` with outputs under `temp_dir`, logging to
/// `log_file` (and stderr, prefixed with the stage name).
StageChild start_stage(const Stage& stage, const std::filesystem::path& work_dir, const std::filesystem::path& temp_dir,
                       const std::filesystem::path& log_file);

/// Turns a reaped child's wait status and resource usage into an outcome.
StageOutcome collect_stage(const StageChild& child, int wait_status, double peak_memory_mb, double duration_s);

}  // namespace stentsim::pipeline
