// `stentsim cohort run|status COHORT.yaml`: many cases with one command.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <optional>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/child_process.hpp"
#include "pipeline/runner.hpp"
#include "workflows/case_config.hpp"
#include "workflows/case_stages.hpp"
#include "workflows/cli/commands.hpp"
#include "workflows/cohort/cohort_runner.hpp"
#include "workflows/cohort/cohort_slurm.hpp"
#include "workflows/study/study_report.hpp"
#include "workflows/version.hpp"

namespace stentsim::cli {
namespace {


std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= s.size()) {
    auto end = s.find(',', start);
    if (end == std::string::npos) end = s.size();
    if (end > start) out.push_back(s.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

/// Stage names given on the command line (--until, --only, --force STAGE),
/// checked against every selected case's plan before anything runs: a
/// misspelt stage would otherwise start every case, fail each one and
/// overwrite the cohort summary. InputError (exit 2) with "did you mean".
void check_stage_names(const workflows::CohortConfig& c, const std::vector<std::string>& only_cases,
                       const std::vector<std::pair<std::string, std::string>>& given) {
  for (const auto i : workflows::selected_cases(c, only_cases)) {
    const auto& k = c.cases[i];
    for (const auto& [option, stage] : given) {
      if (std::find(k.stages.begin(), k.stages.end(), stage) != k.stages.end()) continue;
      std::string list;
      for (const auto& s : k.stages) list += (list.empty() ? "" : ", ") + s;
      const std::string closest = closest_name(k.stages, stage);
      throw InputError(fmt::format("{}: {} '{}' is not a stage of case '{}' (its stages: {}){}", c.file.string(), option, stage,
                                   k.id, list, closest.empty() ? std::string() : fmt::format("; did you mean '{}'?", closest)));
    }
  }
}

int cohort_status(const std::string& file) {
  const auto c = workflows::load_cohort(file);
  // Looking writes nothing: the case files are not (re)materialized here.
  constexpr int kCell = 18;  // fits "failed (expected)"
  std::cout << fmt::format("{:<20}", "case");
  // Slurm: the task of each case and where it stands (squeue for pending/running).
  std::optional<std::vector<workflows::SlurmCaseState>> slurm;
  if (workflows::has_slurm_jobs(c)) slurm = workflows::slurm_case_states(c);
  for (const auto& s : workflows::all_stage_names()) std::cout << fmt::format(" {:<{}}", s, kCell);
  if (slurm) std::cout << fmt::format(" {:<12} {}", "slurm task", "slurm state");
  std::cout << "\n";
  std::vector<std::string> running_notes;
  for (std::size_t i = 0; i < c.cases.size(); ++i) {
    const auto cc = workflows::cohort_case_config(c, c.cases[i]);
    pipeline::Runner r(pipeline::Plan(workflows::stages_for(cc), cc.work_dir), kVersion);
    std::map<std::string, std::string> state;
    const auto& expect = c.cases[i].expect_failure;
    for (const auto& st : r.status())
      state[st.name] = st.state == pipeline::StageState::up_to_date ? "done"
                       : st.state == pipeline::StageState::failed  ? (expect && *expect == st.name ? "failed (expected)" : "failed")
                       : st.state == pipeline::StageState::stale   ? "stale"
                                                                   : "-";
    // Running: a local runner holds the case's work-folder lock; a Slurm task
    // runs on a node whose lock we cannot see, so there squeue says so.
    const auto act = workflows::case_activity(cc.work_dir);
    const bool slurm_running = slurm && (*slurm)[i].state == "running";
    if (act.running || slurm_running) {
      for (const auto& s : act.running ? act.stages : workflows::stages_in_progress(cc.work_dir)) state[s] = "running";
      running_notes.push_back(fmt::format("{}: running ({})", c.cases[i].id,
                                          act.running ? act.holder : "Slurm task " + (*slurm)[i].job));
    }
    std::cout << fmt::format("{:<20}", c.cases[i].id);
    for (const auto& s : workflows::all_stage_names())
      std::cout << fmt::format(" {:<{}}", state.count(s) ? state[s] : "", kCell);
    if (slurm) std::cout << fmt::format(" {:<12} {}", (*slurm)[i].job, (*slurm)[i].state);
    std::cout << "\n";
  }
  for (const auto& n : running_notes) std::cout << n << "\n";
  // Failures and lost tasks with their messages (the tail of run.log or of the Slurm output).
  if (slurm)
    for (const auto& s : *slurm)
      if (!s.detail.empty()) std::cout << fmt::format("{}: {}: {}\n", s.id, s.state, s.detail);
  return 0;
}

}  // namespace

void register_cohort(CLI::App& app) {
  auto* cohort = app.add_subcommand("cohort", "Run many cases (a cohort) with one command");
  cohort->require_subcommand(1);
  struct Args {
    std::string file, cases, until, only;
    std::string force, backend;
    bool dry_run = false, no_wait = false;
    int workers = 0;
  };
  auto a = std::make_shared<Args>();
  auto* run = cohort->add_subcommand("run", "Run every case's pipeline incrementally (local workers or Slurm)");
  run->add_option("cohort", a->file, "Cohort file (YAML)")->required();
  run->add_option("--workers", a->workers, "Worker processes (default: the cohort file's, else the core count)")
      ->check(CLI::Range(1, 1024));
  run->add_option("--cases", a->cases, "Only these case ids (comma-separated)");
  run->add_option("--until", a->until, "Run each case until this stage");
  run->add_option("--only", a->only, "Run only this stage of each case");
  auto* force = run->add_option("--force", a->force, "Re-run every stage, or only STAGE")->expected(0, 1);
  run->add_flag("--dry-run", a->dry_run, "Print each case's plan; run nothing");
  run->add_option("--backend", a->backend, "local (worker pool) or slurm (one job array); default: the cohort file's")
      ->check(CLI::IsMember({"local", "slurm"}));
  run->add_flag("--no-wait", a->no_wait, "slurm: submit and return; follow with `cohort status`");
  on(run, [a, force] {
    auto c = workflows::load_cohort(a->file);
    if (!a->backend.empty()) c.backend = a->backend;
    if (a->no_wait && c.backend != "slurm")
      throw InputError(fmt::format("{}: --no-wait needs the slurm back-end (backend: slurm or --backend slurm)", c.file.string()));
    workflows::CohortRunOptions o;
    o.no_wait = a->no_wait;
    o.dry_run = a->dry_run;
    o.workers = a->workers;
    o.only_cases = split(a->cases);
    o.binary = process::self_executable().string();
    std::vector<std::pair<std::string, std::string>> stage_args;
    if (!a->until.empty()) stage_args.emplace_back("--until", a->until);
    if (!a->only.empty()) stage_args.emplace_back("--only", a->only);
    if (force->count() && !a->force.empty()) stage_args.emplace_back("--force", a->force);
    check_stage_names(c, o.only_cases, stage_args);
    if (!a->until.empty()) o.run_args.insert(o.run_args.end(), {"--until", a->until});
    if (!a->only.empty()) o.run_args.insert(o.run_args.end(), {"--only", a->only});
    if (force->count()) {
      o.run_args.push_back("--force");
      if (!a->force.empty()) o.run_args.push_back(a->force);
    }
    if (a->dry_run) o.run_args.push_back("--dry-run");
    const auto rep = c.backend == "slurm" ? workflows::run_cohort_slurm(c, o, std::cout) : workflows::run_cohort(c, o, std::cout);
    if (!rep.waited) return 0;
    if (a->dry_run) {  // each case's plan, from its log; no summary: nothing ran
      for (const auto& r : rep.cases) {
        std::cout << fmt::format("== {} ==\n", r.id);
        std::ifstream log(c.work_dir / r.id / "run.log");
        std::cout << log.rdbuf();
      }
      return rep.exit_code();
    }
    // The summary keeps one row per case of the cohort, also with --cases.
    auto whole = rep;
    workflows::add_unselected_cases(c, whole);
    workflows::write_cohort_summary(c, whole);
    std::cout << fmt::format("{} cases: {} as expected, {} unexpected failures; summary: {}\n", rep.cases.size(),
                             rep.cases.size() - static_cast<std::size_t>(rep.unexpected()), rep.unexpected(),
                             (c.work_dir / "cohort_summary.csv").string());
    for (const auto& r : rep.cases)
      if (!r.as_expected())
        std::cerr << fmt::format("  {}: {}{}: {}\n  log: {}\n", r.id, r.status, r.failed_stage.empty() ? "" : " at " + r.failed_stage,
                                 r.message, (c.work_dir / r.id / "run.log").string());
    return rep.exit_code();
  });
  auto file = std::make_shared<std::string>();
  auto* status = cohort->add_subcommand("status", "Table of cases x stages (done, stale, failed, running) and, for Slurm, each case's task and state");
  status->add_option("cohort", *file, "Cohort file (YAML)")->required();
  on(status, [file] { return cohort_status(*file); });
}

}  // namespace stentsim::cli
