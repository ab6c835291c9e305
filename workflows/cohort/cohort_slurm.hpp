#pragma once
// The Slurm back-end of `stentsim cohort run` (issue 10): one job array per
// submission (one task per case, `stentsim run` in the case's folder), after a
// one-task probe job has shown that the compute nodes see the work folder and
// the binary. Pending/running comes from squeue (there is no accounting
// database); done/failed from the exit-code file each task writes as its last
// act and from the case's own manifest. A task that left the queue without
// that file was lost (time, memory or node) and is reported with the tail of
// its Slurm output file. Job ids are kept in <work_dir>/cohort_manifest.yaml,
// so a re-run attaches to queued or running tasks and resubmits only
// unfinished or failed cases.
#include <iosfwd>
#include <string>
#include <vector>

#include "workflows/cohort/cohort_runner.hpp"

namespace stentsim::workflows {

/// The batch script of one job array: task i runs case `ids[i]`. With
/// ranks_per_case > 1 it exports STENTSIM_MPI_LAUNCH (mpirun over the task's
/// Slurm allocation) for the MPI stages; the serial stages run once.
std::string slurm_array_script(const CohortConfig& c, const std::vector<std::string>& ids, const std::string& binary,
                               const std::vector<std::string>& run_args);

/// sbatch's arguments for an array of `n` tasks (without the program name and
/// the script), from the cohort's ranks_per_case and `slurm:` settings.
std::vector<std::string> sbatch_array_arguments(const CohortConfig& c, std::size_t n, const std::filesystem::path& output_dir);

/// Submits the selected cases that are not queued, running or up to date (a
/// probe job first), attaches to those still queued or running, and unless
/// o.no_wait waits with progress lines. Returns the outcomes like run_cohort
/// (report.waited false with --no-wait). SIGINT/SIGTERM cancel the tasks it
/// follows (scancel) and throw Interrupted. Throws ComputeError when a Slurm
/// tool is missing, the probe fails or a submission is rejected.
CohortReport run_cohort_slurm(const CohortConfig& c, const CohortRunOptions& o, std::ostream& out);

/// Where a case stands on Slurm, for `cohort status`: its task id ("" when
/// never submitted) and state: pending/running/... from squeue, done/failed
/// from its exit-code file and manifest, "failed (lost: time, memory or
/// node)" otherwise; `detail` holds the failure message or the output's tail.
struct SlurmCaseState {
  std::string id, job, state, detail;
};
std::vector<SlurmCaseState> slurm_case_states(const CohortConfig& c);

/// True when <work_dir>/cohort_manifest.yaml records Slurm jobs.
bool has_slurm_jobs(const CohortConfig& c);

}  // namespace stentsim::workflows
