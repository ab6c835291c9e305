#pragma once
// The make-like runner: decides which stages are stale, runs them (in child
// processes, up to --jobs at once), renames their outputs into place on
// success and records everything in the case's manifest.
#include <iosfwd>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "pipeline/manifest.hpp"
#include "pipeline/plan.hpp"

namespace stentsim::pipeline {

struct RunOptions {
  std::optional<std::string> until;  // run this stage and what it needs
  std::optional<std::string> only;   // run just this stage (its inputs must exist)
  bool force_all = false;            // run every selected stage
  std::set<std::string> force;       // run these even if up to date
  bool dry_run = false;              // print the plan and why, run nothing
  int jobs = 1;                      // independent stages at once
  /// After a failure, go on with every stage that does not need the failed
  /// one (mesh and fibers need no placement); the exit code stays 1.
  bool keep_going = false;
};

enum class StageState { up_to_date, stale, failed, never_run };
const char* to_string(StageState s);

struct StageStatus {
  std::string name;
  StageState state;
  std::vector<std::string> reasons;
  std::optional<StageRecord> record;
};

struct RunReport {
  std::vector<std::string> ran, skipped, failed;
  std::vector<std::string> blocked;  // not run: they need a failed stage (keep_going)
  bool interrupted = false;
  std::string first_failure;  // "stage: message"
  ErrorKind first_failure_kind = ErrorKind::none;
  /// 0 success, 1 a stage failed, 130 interrupted.
  int exit_code() const { return interrupted ? 130 : failed.empty() ? 0 : 1; }
};

class Runner {
 public:
  Runner(Plan plan, std::string tool_version);

  /// State of every stage as it stands (no run). A stage downstream of a stale
  /// one is reported stale ("upstream X is stale").
  std::vector<StageStatus> status() const;
  /// Runs what is needed; progress and the plan go to `out`.
  RunReport run(const RunOptions& options, std::ostream& out);

  const Plan& plan() const { return plan_; }
  std::filesystem::path manifest_file() const { return plan_.work_dir() / "manifest.yaml"; }

 private:
  std::set<std::size_t> selection(const RunOptions& o) const;

  Plan plan_;
  std::string tool_version_;
};

}  // namespace stentsim::pipeline
