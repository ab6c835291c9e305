#pragma once
// The Slurm back-end of `stentsim cohort run` (issue 10): one batch job per
// case running `stentsim run` in the case's folder. Pending/running comes
// from squeue (there is no accounting database); done/failed from the exit
// code file each job writes and from the case's own manifest. A job that left
// the queue without an exit code file was lost (time, memory or node) and is
// reported with the tail of its Slurm output file.
#include <iosfwd>
#include <string>
#include <vector>

#include "workflows/cohort/cohort_runner.hpp"

namespace stentsim::workflows {

/// The batch script of one case (written to <work_dir>/<id>/slurm_job.sh).
std::string slurm_batch_script(const CohortConfig& c, const CohortCase& k, const std::string& binary,
                               const std::filesystem::path& case_file, const std::vector<std::string>& run_args);

/// sbatch's arguments for one case (without the program name), from the cohort's `slurm:` settings.
std::vector<std::string> sbatch_arguments(const CohortConfig& c, const CohortCase& k);

/// Submits every selected case, waits with a progress line, and returns the
/// outcomes like run_cohort. SIGINT/SIGTERM cancel the submitted jobs (scancel)
/// and throw Interrupted. Throws ComputeError when sbatch is missing or a
/// submission fails (the jobs already submitted are cancelled).
CohortReport run_cohort_slurm(const CohortConfig& c, const CohortRunOptions& o, std::ostream& out);

}  // namespace stentsim::workflows
