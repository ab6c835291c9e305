#pragma once
// Runs a cohort's cases with the same incremental runner as one case, on a
// pool of local worker processes (each `stentsim run` of one case), records
// each case's outcome and writes cohort_summary.csv.
#include <iosfwd>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "workflows/cohort/cohort_config.hpp"

namespace stentsim::workflows {

struct CohortRunOptions {
  int workers = 0;                      // 0: from the cohort file, else the core count
  std::vector<std::string> only_cases;  // --cases
  std::vector<std::string> run_args;    // passed to each `stentsim run` (--until, --only, --force, --dry-run)
  std::string binary;                   // the stentsim executable
  bool no_wait = false;                 // slurm: submit and return (`cohort status` follows)
  bool dry_run = false;                 // local: each case prints its plan (run_args has --dry-run);
                                        // slurm: print what would be submitted, submit nothing
};

struct CaseOutcome {
  std::string id;
  std::string status;        // done | failed | failed as expected | succeeded unexpectedly | interrupted
  std::string failed_stage;  // from the case's manifest
  /// Why it failed (empty when it did not): the failed stage's kind from the manifest
  /// (input: a bad input file or setting, compute, crash, unknown), input for a case file
  /// `stentsim run` refused (exit 2), crash for a killed worker, interrupted, lost (Slurm),
  /// unknown when the manifest that would say could not be read.
  std::string error_kind;
  std::string message;       // last lines of the case's log on failure
  std::string manifest_error;  // why the case's manifest, needed for its outcome, could not be read (empty: it could); status failed then
  int exit_code = 0;         // the case's `stentsim run`: its exit status, 128 + signal when killed, -1 unknown (lost)
  double wall_s = 0;
  bool as_expected() const { return status == "done" || status == "failed as expected"; }
};

struct CohortReport {
  std::vector<CaseOutcome> cases;
  bool waited = true;  // false: submitted with --no-wait, outcomes not known yet
  int unexpected() const;
  int exit_code() const { return unexpected() ? 1 : 0; }
};

/// The outcome of one case from its exit status and its manifest (shared by
/// the back-ends): status, failed stage and the last lines of its run.log.
CaseOutcome case_outcome(const CohortConfig& c, const CohortCase& k, int exit_code, double wall_s);

/// Indices of the cases to run (all, or those --cases names; unknown ids are an InputError).
std::vector<std::size_t> selected_cases(const CohortConfig& c, const std::vector<std::string>& only);

/// Orders outcomes as the cases appear in the cohort file.
void sort_like_cohort(const CohortConfig& c, std::vector<CaseOutcome>& cases);


/// Concurrent cases: min(workers, cores / ranks_per_case), at least 1.
int concurrent_cases(int workers, int ranks_per_case, int cores);

/// Whether a case's runner is at work now, from its work-folder lock
/// (pipeline/work_lock.hpp: an flock held by the running `stentsim run`,
/// released by the kernel when it dies; found in /proc/locks, so looking never
/// takes the lock) and the stages it is running (their temporary output
/// folders .tmp/<stage>, which exist only while a stage runs). `holder` is the
/// lock file's text ("pid N on HOST since T"). Local file systems only: a run
/// on another node (Slurm) shows through squeue instead.
struct CaseActivity {
  bool running = false;
  std::string holder;
  std::vector<std::string> stages;
};
CaseActivity case_activity(const std::filesystem::path& case_work_dir);
/// The stages with a temporary output folder under case_work_dir/.tmp.
std::vector<std::string> stages_in_progress(const std::filesystem::path& case_work_dir);

/// ETA from the median stage times so far (issue 10): `samples` holds, per
/// stage, the durations of the runs that finished since the cohort run began;
/// each unfinished case still needs every sampled stage it has not finished
/// (`finished[i]`), at the median time; `parallel` cases run at once.
/// nullopt before any stage has finished.
std::optional<double> cohort_eta(const std::map<std::string, std::vector<double>>& samples,
                                 const std::vector<std::set<std::string>>& finished, int parallel);

/// Reads a case's manifest: the stages that finished ok at or after `since`
/// (ISO 8601 UTC) with their durations.
std::map<std::string, double> stages_finished_since(const std::filesystem::path& manifest_file, const std::string& since);

CohortReport run_cohort(const CohortConfig& c, const CohortRunOptions& o, std::ostream& out);

/// The cohort summary as a table: fixed columns (case, status, exit_code,
/// failed_stage, error_kind, message, wall_time_s, inputs: the merged case's `input`
/// section as "key=value; ..." with files by name), then "override.<dotted
/// key>" for every key any case overrides (files by name, a removed key
/// "null"), then "<stage>.<qoi> [unit]" for every QoI any case's stage
/// summaries hold, and "<stage>.wall_time_s"; one row per case.
struct CohortTable {
  std::vector<std::string> columns;
  std::vector<std::map<std::string, std::string>> rows;  // column -> cell
};
CohortTable cohort_table(const CohortConfig& c, const CohortReport& r);
/// The table's fixed columns, in order (no statistics, no plots).
const std::vector<std::string>& cohort_fixed_columns();

/// Adds the cases a run with --cases left out, so that the cohort summary
/// keeps one row per case of the cohort: each from its row of the previous
/// cohort_summary.csv when there is one (status, exit code, failed stage,
/// message, wall time; its QoIs come from its stage summaries as they stand),
/// else from its manifest ("done", or "failed"/"failed as expected" at its
/// failed stage), else "not run". Call before write_cohort_summary and after
/// taking the exit code: these cases were not part of this run.
void add_unselected_cases(const CohortConfig& c, CohortReport& r);

/// Writes <work_dir>/cohort_summary.csv (the table above), then
/// cohort_summary.md and one PNG per numeric QoI beside it (cohort_plots.hpp).
void write_cohort_summary(const CohortConfig& c, const CohortReport& r);

}  // namespace stentsim::workflows
