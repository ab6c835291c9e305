// `stentsim run CASE.yaml` and `stentsim status CASE.yaml`: the per-patient
// command on the make-like runner.
#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <iostream>

#include "common/error.hpp"
#include "pipeline/runner.hpp"
#include "workflows/case_config.hpp"
#include "workflows/case_stages.hpp"
#include "workflows/cli/commands.hpp"
#include "workflows/version.hpp"

namespace stentsim::cli {
namespace {

struct RunArgs {
  std::string case_file;
  std::string until, only;
  std::string force;  // --force [STAGE]: empty with the flag given = every stage
  bool dry_run = false;
  int jobs = 1;
  bool keep_going = false;
};

pipeline::Runner make_runner(const workflows::CaseConfig& c) {
  return pipeline::Runner(pipeline::Plan(workflows::stages_for(c), c.work_dir), kVersion);
}

int run_case(RunArgs& a, bool force_given) {
  // "--force CASE.yaml" with no stage: the parser gives the file to --force.
  if (a.case_file.empty() && !a.force.empty() && std::filesystem::is_regular_file(a.force)) {
    a.case_file = a.force;
    a.force.clear();
  }
  if (a.case_file.empty()) throw InputError("run: the case file is missing (stentsim run CASE.yaml)");
  const auto t0 = std::chrono::steady_clock::now();
  const auto c = workflows::load_case(a.case_file);
  auto runner = make_runner(c);
  pipeline::RunOptions o;
  if (!a.until.empty()) o.until = a.until;
  if (!a.only.empty()) o.only = a.only;
  o.force_all = force_given && a.force.empty();
  if (!a.force.empty()) o.force.insert(a.force);
  o.dry_run = a.dry_run;
  o.jobs = a.jobs;
  o.keep_going = a.keep_going;
  std::cout << fmt::format("case {} ({} scene), work folder {}\n", c.name, workflows::to_string(c.scene), c.work_dir.string());
  const auto report = runner.run(o, std::cout);
  if (a.dry_run) return 0;
  const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << fmt::format("{} ran, {} up to date, {} failed{} in {:.2f} s\n", report.ran.size(), report.skipped.size(),
                           report.failed.size(),
                           report.blocked.empty() ? "" : fmt::format(", {} not run (they need a failed stage)", report.blocked.size()),
                           dt);
  if (report.interrupted) std::cerr << "interrupted: finished stages are kept; run again to resume\n";
  if (!report.first_failure.empty()) std::cerr << "error: stage " << report.first_failure << "\n";
  return report.exit_code();
}

int status_case(const std::string& file) {
  const auto c = workflows::load_case(file);
  auto runner = make_runner(c);
  std::cout << fmt::format("case {} ({} scene), work folder {}\n", c.name, workflows::to_string(c.scene), c.work_dir.string());
  for (const auto& st : runner.status()) {
    std::string detail;
    if (st.state == pipeline::StageState::up_to_date && st.record)
      detail = fmt::format("{:.2f} s, {:.0f} MB, {}", st.record->duration_s, st.record->peak_memory_mb, st.record->finished);
    else if (!st.reasons.empty())
      detail = st.reasons.front() + (st.reasons.size() > 1 ? fmt::format(" (+{} more)", st.reasons.size() - 1) : "");
    std::cout << fmt::format("  {:<13} {:<11} {}\n", st.name, pipeline::to_string(st.state), detail);
  }
  return 0;
}

}  // namespace

void register_run(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  auto* run = app.add_subcommand("run", "Run a case's pipeline; re-runs only what is stale");
  run->add_option("case", args->case_file, "Case file (YAML)");
  run->add_option("--until", args->until, "Run this stage and the stages it needs, then stop");
  run->add_option("--only", args->only, "Run only this stage (its inputs must exist)");
  auto* force = run->add_option("--force", args->force, "Re-run every stage, or only STAGE")->expected(0, 1);
  run->get_option("--until")->check(CLI::Validator([](std::string& v) { return v.empty() ? "a stage name is required" : ""; }, "STAGE"));
  run->get_option("--only")->check(CLI::Validator([](std::string& v) { return v.empty() ? "a stage name is required" : ""; }, "STAGE"));
  run->add_flag("--dry-run", args->dry_run, "Print the plan and why each stage would run; run nothing");
  run->add_option("--jobs,-j", args->jobs, "Independent stages to run at once")->check(CLI::Range(1, 64));
  run->add_flag("--keep-going,-k", args->keep_going,
                "After a failure, run every stage that does not need the failed one (the exit code stays 1)");
  on(run, [args, force] { return run_case(*args, force->count() > 0); });

  auto file = std::make_shared<std::string>();
  auto* status = app.add_subcommand("status", "Show each stage as up to date, stale (and why) or failed");
  status->add_option("case", *file, "Case file (YAML)")->required();
  on(status, [file] { return status_case(*file); });
}

}  // namespace stentsim::cli
