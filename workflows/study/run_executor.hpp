#pragma once
// Runs the points of a study as child processes (fork + exec of stentsim,
// under mpirun for ranks > 1), never with more ranks in flight than cores so
// that timings do not share cores. Each run lives in OUT/runs/<key>/ (its
// input, run.log, the command's outputs and summary.yaml) and ends with
// result.yaml (status, timings, host, load, binary version, QoIs), written
// last: a run with a result.yaml from this host and binary is not run again.
#include <filesystem>
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "workflows/study/study_config.hpp"
#include "workflows/study/study_runs.hpp"

namespace stentsim::study {

struct HostInfo {
  std::string host;
  int nproc = 1;
  std::string version;  ///< kVersion + "+" + hash of the stentsim binary
};

/// This machine and the binary that runs the studies.
HostInfo this_host(const std::string& binary);

struct RunResult {
  std::string status;   ///< "ok" or "failed"
  std::string message;  ///< failure reason (tail of run.log)
  double wall_s = 0, cpu_s = 0, peak_memory_mb = 0;
  /// How peak_memory_mb was found: "wait4" (one process, or the largest of
  /// mpirun's tree) or "sum over N ranks" (each rank's own peak, summary.yaml).
  std::string peak_memory_rule;
  std::string host, version;
  int nproc = 0;
  double load_average = 0;  ///< 1-minute load when the run started
  std::map<std::string, std::vector<double>> qoi;  ///< numeric QoIs of summary.yaml
  bool cached = false;
};

struct ExecOptions {
  std::string binary;          ///< the stentsim executable
  int jobs = 1;                ///< runs at once (still bounded by cores / ranks)
  int cores = 0;               ///< 0: the machine's core count
  bool reuse_timings = false;  ///< accept cached rows from another host or binary
  std::ostream* out = nullptr; ///< progress lines
};

struct ExecStats {
  int executed = 0, cached = 0, failed = 0;
  int max_ranks_in_flight = 0;
};

/// The cached result of the run folder `dir` if it is usable (same host and
/// binary, or reuse_timings); failed runs are never reused.
std::optional<RunResult> cached_result(const std::filesystem::path& dir, const HostInfo& host, bool reuse_timings);

/// Runs what is not cached; fills `results` (one per plan run). Throws
/// InputError when a run needs more ranks than there are cores, Interrupted
/// on SIGINT/SIGTERM (the children's process groups are stopped first).
ExecStats execute_runs(const StudyConfig& study, const StudyPlan& plan, const std::filesystem::path& out_dir,
                       const ExecOptions& options, std::vector<RunResult>& results);

/// The summary.yaml QoI in which an MPI command reports each rank's peak memory (MB).
inline constexpr const char* kPerRankMemoryQoi = "peak_memory_mb_per_rank";

/// For a run of `ranks` > 1 MPI ranks: the peak memory is the sum over ranks
/// of the peaks the command reports in kPerRankMemoryQoi (issue 11), else
/// wait4's value stays (the largest process) and the rule says why.
void apply_rank_memory(RunResult& result, int ranks);

/// Folder of a run.
std::filesystem::path run_dir(const std::filesystem::path& out_dir, const RunSpec& run);

}  // namespace stentsim::study
