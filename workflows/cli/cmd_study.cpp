// `stentsim study error STUDY.yaml`: error against run time over knobs of a
// base scene or case, and `stentsim study stability [...]`: the stiff and
// extreme cases (workflows/study/stability/, which parses its own words).
#include <fmt/format.h>
#include <unistd.h>

#include <iostream>

#include "common/error.hpp"
#include "common/child_process.hpp"
#include "workflows/cli/commands.hpp"
#include "workflows/study/error_study.hpp"
#include "workflows/study/stability/stability_command.hpp"

namespace stentsim::cli {
namespace {


}  // namespace

void register_study(CLI::App& app) {
  auto* study = app.add_subcommand("study", "Studies over many runs: error against run time, numerical stability");
  study->require_subcommand(1);
  struct Args {
    std::string file, out;
    bool dry_run = false, yes = false, reuse = false;
    int jobs = 1;
  };
  auto a = std::make_shared<Args>();
  auto* err = study->add_subcommand("error", "Error against run time: vary knobs of a base scene, compare with a reference");
  err->add_option("study", a->file, "Study file (YAML)")->required();
  err->add_option("--out", a->out, "Output folder (default: <study folder>/<name>.study)");
  err->add_flag("--dry-run", a->dry_run, "List the runs with estimated times; run nothing");
  err->add_flag("--yes", a->yes, "Allow more than 50 runs");
  err->add_flag("--reuse-timings", a->reuse, "Keep cached rows measured on another host or binary");
  err->add_option("--jobs", a->jobs, "Runs at once (ranks in flight never exceed the cores)")->check(CLI::Range(1, 1024));
  on(err, [a] {
    study::ErrorStudyOptions o;
    o.out_dir = a->out;
    o.dry_run = a->dry_run;
    o.yes = a->yes;
    o.reuse_timings = a->reuse;
    o.jobs = a->jobs;
    o.binary = process::self_executable().string();
    return study::run_error_study(a->file, o, std::cout);
  });
  auto* stab = study->add_subcommand("stability", "Stiff and extreme cases: converge or fail cleanly (suite, outcome table)");
  stab->prefix_command();  // every word after `study stability` goes to the stability command
  stab->set_help_flag();    // including --help
  on(stab, [stab] { return study::run_stability_command(stab->remaining()); });
}

}  // namespace stentsim::cli
