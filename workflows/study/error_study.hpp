#pragma once
// `stentsim study error STUDY.yaml`: plan, (dry-run estimate,) run what is not
// cached, evaluate and report (study.csv, study.md, plots).
#include <filesystem>
#include <iosfwd>
#include <string>

#include "common/summary.hpp"
#include "workflows/study/run_executor.hpp"
#include "workflows/study/study_report.hpp"

namespace stentsim::study {

struct ErrorStudyOptions {
  std::filesystem::path out_dir;  ///< empty: <study file's folder>/<name>.study
  bool dry_run = false;
  bool yes = false;               ///< allow more than kMaxRunsWithoutYes runs
  bool reuse_timings = false;
  int jobs = 1;
  int cores = 0;                  ///< 0: the machine's
  std::string binary;             ///< the stentsim executable
};

inline constexpr std::size_t kMaxRunsWithoutYes = 50;

struct ErrorStudyResult {
  StudyPlan plan;
  std::vector<RunResult> results;
  StudyOutcome outcome;
  ReportFiles files;
  ExecStats stats;
  std::filesystem::path out_dir;
};

/// The study's summary.yaml (DESIGN.md §6): run counts (executed, cached,
/// failed), the fitted (and Richardson) order per refinement line, the
/// smallest error and the cheapest run within the tolerance.
Summary error_study_summary(const StudyConfig& study, const ErrorStudyResult& result);

/// Runs the study; prints progress and a summary to `out`. Returns the exit
/// code: 0 when every run succeeded, 1 when some failed (they are in the table).
/// A run whose summary.yaml lacks the study's `qoi` counts as failed (message
/// names the QoI, the run and the QoIs present), so a typo'd QoI exits 1.
/// A dry run only prints the runs with estimated times (result has no files).
int run_error_study(const std::filesystem::path& study_file, const ErrorStudyOptions& options, std::ostream& out,
                    ErrorStudyResult* result = nullptr);

/// Estimated seconds of a run from measured rows in the study's cache: its
/// own, else the nearest measured run (fewest knobs differing) scaled by the
/// refinement knobs' cost exponents; negative when nothing was measured yet.
double estimate_seconds(const StudyConfig& study, const StudyPlan& plan, std::size_t run,
                        const std::vector<std::optional<double>>& measured);

}  // namespace stentsim::study
