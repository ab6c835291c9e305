#include "workflows/cohort/cohort_slurm.hpp"

#include <fmt/format.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <ostream>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include "common/child_process.hpp"
#include "common/error.hpp"
#include "common/stop_signals.hpp"
#include "common/files.hpp"
#include "pipeline/manifest.hpp"
#include "pipeline/runner.hpp"
#include "workflows/case_config.hpp"
#include "workflows/case_stages.hpp"
#include "workflows/version.hpp"

namespace fs = std::filesystem;

namespace stentsim::workflows {
namespace {

const char* const kLost = "failed (lost: time, memory or node)";

// Single quotes for bash: 'it'\''s'.
std::string sh_quote(const std::string& s) {
  std::string q = "'";
  for (char ch : s) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

std::string find_in_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string d; std::getline(dirs, d, ':');) {
    const fs::path p = fs::path(d.empty() ? "." : d) / program;
    if (::access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

struct CommandResult {
  int code = 0;
  std::string output;  // stdout and stderr together
};

// A Slurm command's time to answer: slurmctld answers in well under a second when it
// is up; one that hangs (a controller failing over, a stalled RPC) must not hang the
// follower, which then waits out slurm.queue_patience_s as for a failed squeue.
constexpr double kCommandLimitS = 120.0;

// Runs a Slurm command (no shell) and captures its output; code is the exit
// status, 128 + the signal that ended it, 124 (as timeout(1)) when it did not
// answer within kCommandLimitS.
CommandResult run_command(const std::vector<std::string>& argv) {
  const auto run = process::run_captured(argv, {}, kCommandLimitS);
  if (run.end.timed_out)
    return {124, run.output + fmt::format("{}(no answer within {:.0f} s)", run.output.empty() ? "" : "\n", kCommandLimitS)};
  return {run.end.signal ? 128 + run.end.signal : run.end.exit_code, run.output};
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '\r')) s.pop_back();
  return s;
}

std::string tail_of(const fs::path& file, std::size_t n) {
  std::error_code ec;  // a shared file system's error must not end the follower (it would cancel the array)
  if (!fs::exists(file, ec)) return "(no Slurm output file " + file.string() + (ec ? ": " + ec.message() : "") + ")";
  const std::string tail = files::log_tail(file, n);
  return tail.empty() ? "(empty Slurm output " + file.string() + ")" : tail;
}

// States in which a job still holds (or waits for) resources.
bool active_state(const std::string& s) {
  static const std::set<std::string> active = {"PENDING", "CONFIGURING", "RUNNING", "COMPLETING", "SUSPENDED",
                                               "REQUEUED", "REQUEUE_HOLD", "REQUEUE_FED", "RESIZING", "SIGNALING",
                                               "STAGE_OUT", "STOPPED"};
  return active.count(s) > 0;
}

// Task id ("123_4") -> state for every task of the given array jobs that
// squeue still lists; a task missing from the map has left the queue.
std::map<std::string, std::string> task_states(const std::set<std::string>& arrays) {
  std::map<std::string, std::string> states;
  for (const auto& a : arrays) {  // one query per array: squeue rejects a list once one id is purged
    const auto r = run_command({"squeue", "-h", "-r", "-t", "all", "-j", a, "-o", "%i %T"});
    if (r.code != 0) {
      if (r.output.find("Invalid job id") != std::string::npos) continue;  // purged: every task left
      throw ComputeError("cohort (slurm): squeue failed (exit " + std::to_string(r.code) + "): " + trim(r.output));
    }
    std::istringstream in(r.output);
    for (std::string id, state; in >> id >> state;) states[id] = state;
  }
  return states;
}

void cancel(const std::vector<std::string>& tasks, std::ostream& out) {
  if (tasks.empty()) return;
  std::vector<std::string> argv = {"scancel"};
  argv.insert(argv.end(), tasks.begin(), tasks.end());
  const auto r = run_command(argv);
  out << fmt::format("cancelled {} Slurm task(s){}\n", tasks.size(), r.code ? ": scancel said " + trim(r.output) : "");
  out.flush();
}

// The follower gave up on a queue that stopped answering.
struct QueueUnreachable : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void sleep_interruptibly(double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!process::StopSignals::received() && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

// ---- the cohort manifest: which Slurm task ran (or runs) each case -------

struct TaskRecord {
  std::string job;    // "123_4"
  std::string array;  // "123"
  fs::path output;    // the task's Slurm output file
  std::vector<std::string> run_args;
  std::string submitted;  // ISO 8601 UTC
};

fs::path manifest_path(const CohortConfig& c) { return c.work_dir / "cohort_manifest.yaml"; }

std::map<std::string, TaskRecord> load_tasks(const CohortConfig& c) {
  std::map<std::string, TaskRecord> tasks;
  const fs::path f = manifest_path(c);
  if (!fs::exists(f)) return tasks;
  YAML::Node root;
  try {
    root = YAML::LoadFile(f.string());
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}: unreadable cohort manifest ({}); delete it to start afresh", f.string(), e.what()));
  }
  for (const auto& kv : root["slurm_tasks"]) {
    TaskRecord t;
    t.job = kv.second["job"].as<std::string>("");
    t.array = kv.second["array_job"].as<std::string>("");
    t.output = kv.second["output"].as<std::string>("");
    t.submitted = kv.second["submitted"].as<std::string>("");
    for (const auto& a : kv.second["run_args"]) t.run_args.push_back(a.as<std::string>());
    if (!t.job.empty()) tasks[kv.first.as<std::string>()] = t;
  }
  return tasks;
}

void save_tasks(const CohortConfig& c, const std::map<std::string, TaskRecord>& tasks) {
  YAML::Emitter e;
  e << YAML::Comment("written by stentsim cohort run (slurm back-end): the Slurm task of each case");
  e << YAML::BeginMap << YAML::Key << "cohort" << YAML::Value << c.file.string();
  e << YAML::Key << "slurm_tasks" << YAML::Value << YAML::BeginMap;
  for (const auto& [id, t] : tasks) {
    e << YAML::Key << id << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "job" << YAML::Value << YAML::DoubleQuoted << t.job;
    e << YAML::Key << "array_job" << YAML::Value << YAML::DoubleQuoted << t.array;
    e << YAML::Key << "output" << YAML::Value << t.output.string();
    e << YAML::Key << "submitted" << YAML::Value << t.submitted;
    e << YAML::Key << "run_args" << YAML::Value << YAML::Flow << t.run_args;
    e << YAML::EndMap;
  }
  e << YAML::EndMap << YAML::EndMap;
  files::write_atomic(manifest_path(c), std::string(e.c_str()) + "\n");
}

// The exit code a task wrote as its last act ("<rc> <task id>"), if that
// file belongs to `job`.
std::optional<int> task_exit_code(const CohortConfig& c, const std::string& id, const std::string& job) {
  std::ifstream in(c.work_dir / id / "exit_code");
  int rc = 0;
  std::string who;
  if (in >> rc >> who && who == job) return rc;
  return std::nullopt;
}

// The outcome of a task that left the queue (nullopt: no exit-code file yet).
std::optional<CaseOutcome> finished_outcome(const CohortConfig& c, const CohortCase& k, const TaskRecord& t, double wall) {
  if (auto rc = task_exit_code(c, k.id, t.job)) return case_outcome(c, k, *rc, wall);
  return std::nullopt;
}

CaseOutcome lost_outcome(const CohortCase& k, const TaskRecord& t, const std::string& state, double wall) {
  CaseOutcome r;
  r.id = k.id;
  r.wall_s = wall;
  r.exit_code = -1;  // unknown: the task never wrote its exit code
  r.status = "failed";
  r.error_kind = "lost";
  r.message = fmt::format("lost: time, memory or node (Slurm task {} {}); Slurm output: {}", t.job, state,
                          tail_of(t.output, 3));
  return r;
}

// True when a case's recorded run needs no new submission: it ended as
// expected with the same run arguments and none of its stages is stale (its
// inputs, configuration or the tool changed) or failed unexpectedly.
bool up_to_date(const CohortConfig& c, const CohortCase& k, const fs::path& case_file, const TaskRecord& t,
                const std::vector<std::string>& run_args) {
  if (t.run_args != run_args) return false;
  const auto rc = task_exit_code(c, k.id, t.job);
  if (!rc) return false;
  const CaseOutcome o = case_outcome(c, k, *rc, 0);
  if (!o.as_expected()) return false;
  const auto cc = load_case(case_file);
  try {
    pipeline::Runner runner(pipeline::Plan(stages_for(cc), cc.work_dir), kVersion);
    for (const auto& s : runner.status()) {
      if (s.state == pipeline::StageState::stale) return false;
      if (s.state == pipeline::StageState::failed && o.status != "failed as expected") return false;
    }
  } catch (const std::exception&) {
    return false;  // a manifest that cannot be read: submit the case again, whose run reports it
  }
  return true;
}

std::string random_token() {
  std::random_device rd;
  return fmt::format("stentsim-probe-{:08x}{:08x}-{}", rd(), rd(), ::getpid());
}

// sbatch options shared by the probe and the array: where and how long.
std::vector<std::string> placement_options(const CohortConfig& c) {
  std::vector<std::string> a;
  if (!c.slurm.partition.empty()) a.push_back("--partition=" + c.slurm.partition);
  if (!c.slurm.time_limit.empty()) a.push_back("--time=" + c.slurm.time_limit);
  return a;
}

// The probe: one task that reads a token file from the work folder and checks
// the binary; its exit code says what the compute node could not see.
void probe(const CohortConfig& c, const std::string& binary, std::ostream& out) {
  const fs::path dir = c.work_dir / "slurm";
  const fs::path token_file = dir / "probe_token";
  const std::string token = random_token();
  files::write_atomic(token_file, token + "\n");
  const fs::path script = dir / "probe.sh";
  files::write_atomic(script, fmt::format("#!/bin/bash\n"
                                          "# generated by stentsim cohort: can a compute node see the work folder?\n"
                                          "[ -r {0} ] || exit 3\n"
                                          "[ \"$(cat {0})\" = {1} ] || exit 4\n"
                                          "[ -x {2} ] || exit 5\n"
                                          "exit 0\n",
                                          sh_quote(token_file.string()), sh_quote(token), sh_quote(binary)));
  // Output to /dev/null and chdir to /: the probe must not need the folder it tests.
  std::vector<std::string> argv = {"sbatch", "--parsable", "--job-name=stentsim-probe-" + c.name, "--output=/dev/null",
                                   "--chdir=/", "--ntasks=1"};
  const auto place = placement_options(c);
  argv.insert(argv.end(), place.begin(), place.end());
  // The cohort's extra options (account, qos, ...) apply too, but never a hold: the runner waits for the probe.
  for (const auto& x : c.slurm.extra_options)
    if (x != "--hold" && x != "-H") argv.push_back(x);
  argv.push_back(script.string());
  const auto r = run_command(argv);
  const std::string job = trim(r.output).substr(0, trim(r.output).find(';'));
  if (r.code != 0 || job.empty() || job.find_first_not_of("0123456789") != std::string::npos)
    throw ComputeError(fmt::format("{}: probe job: sbatch failed (exit {}): {}", c.file.string(), r.code, trim(r.output)));
  out << fmt::format("probe job {}: can the compute nodes see {}?\n", job, c.work_dir.string());
  out.flush();
  std::string state, exit_code;
  for (;;) {
    if (process::StopSignals::received()) {
      cancel({job}, out);
      throw Interrupted();
    }
    const auto s = run_command({"scontrol", "-o", "show", "job", job});
    auto field = [&](const std::string& key) {
      const auto p = s.output.find(" " + key + "=");
      if (p == std::string::npos) return std::string();
      const auto b = p + key.size() + 2;
      return s.output.substr(b, s.output.find_first_of(" \n", b) - b);
    };
    state = field("JobState");
    exit_code = field("ExitCode");
    if (s.code != 0)
      throw ComputeError(fmt::format("{}: probe job {}: scontrol failed: {}", c.file.string(), job, trim(s.output)));
    if (!state.empty() && !active_state(state)) break;
    sleep_interruptibly(std::min(c.slurm.poll_interval_s, 0.5));
  }
  const int rc = std::atoi(exit_code.c_str());  // "3:0" -> 3
  if (state == "COMPLETED" && rc == 0) return;
  const std::string why = rc == 3   ? fmt::format("could not read the token file {}", token_file.string())
                          : rc == 4 ? fmt::format("read a different token from {} (another file system?)", token_file.string())
                          : rc == 5 ? fmt::format("could not execute the stentsim binary {}", binary)
                                    : fmt::format("ended {} with exit code {}", state, exit_code);
  throw ComputeError(fmt::format(
      "{}: the Slurm compute nodes cannot use this cohort: probe job {} {}. The work folder ({}) and the stentsim "
      "binary must be on a file system the compute nodes share (set work_dir in the cohort file)",
      c.file.string(), job, why, c.work_dir.string()));
}

std::string utc_now() { return pipeline::utc_now_iso8601(); }

}  // namespace

std::string slurm_array_script(const CohortConfig& c, const std::vector<std::string>& ids, const std::string& binary,
                               const std::vector<std::string>& run_args) {
  std::string cases;
  for (const auto& id : ids) cases += " " + sh_quote(id);
  std::string cmd = sh_quote(binary) + " run case.yaml";
  for (const auto& a : run_args) cmd += " " + sh_quote(a);
  // The serial stages run once per task; an MPI stage launches its ranks over
  // the task's allocation (--ntasks) with this launcher (mpirun as root needs
  // --allow-run-as-root; Debian's OpenMPI does not work with srun --mpi=pmi2).
  const std::string mpi =
      c.ranks_per_case > 1
          ? "export STENTSIM_MPI_LAUNCH=\"mpirun --allow-run-as-root --oversubscribe -np ${SLURM_NTASKS:-" +
                std::to_string(c.ranks_per_case) + "}\"\n"
          : "";
  std::string threads;  // one thread per library, as for the local workers
  for (const auto& [k, v] : process::single_thread_environment()) threads += "export " + k + "=" + sh_quote(v) + "\n";
  // The exit-code file ("<rc> <task id>", temp + rename) is the task's last
  // act: its absence after the task left the queue means the task was lost.
  return fmt::format(
      "#!/bin/bash\n"
      "# generated by stentsim cohort (slurm back-end) for {}; do not edit\n"
      "cases=({} )\n"
      "id=${{cases[$SLURM_ARRAY_TASK_ID]}}\n"
      "task=${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}}\n"
      "echo \"stentsim cohort task $task: case $id on $(hostname)\"\n"
      "{}"
      "{}"
      "cd {}/\"$id\" || exit 2\n"
      "{} > run.log 2>&1\n"
      "rc=$?\n"
      "echo \"$rc $task\" > .exit_code.tmp && mv -f .exit_code.tmp exit_code\n"
      "echo \"case $id: exit $rc\"\n"
      "exit $rc\n",
      c.file.string(), cases, threads, mpi, sh_quote(c.work_dir.string()), cmd);
}

std::vector<std::string> sbatch_array_arguments(const CohortConfig& c, std::size_t n, const fs::path& output_dir) {
  std::vector<std::string> a = {"--parsable",
                                "--job-name=stentsim-" + c.name,
                                "--array=0-" + std::to_string(n - 1),
                                "--output=" + (output_dir / "slurm-%A_%a.out").string(),
                                "--chdir=" + c.work_dir.string(),
                                "--ntasks=" + std::to_string(c.ranks_per_case),
                                "--cpus-per-task=" + std::to_string(c.slurm.cpus_per_case)};
  const auto place = placement_options(c);
  a.insert(a.end(), place.begin(), place.end());
  if (!c.slurm.memory.empty()) a.push_back("--mem=" + c.slurm.memory);
  a.insert(a.end(), c.slurm.extra_options.begin(), c.slurm.extra_options.end());
  return a;
}

bool has_slurm_jobs(const CohortConfig& c) { return !load_tasks(c).empty(); }

std::vector<SlurmCaseState> slurm_case_states(const CohortConfig& c) {
  const auto tasks = load_tasks(c);
  std::set<std::string> arrays;
  for (const auto& [id, t] : tasks) arrays.insert(t.array);
  std::map<std::string, std::string> states;
  std::string queue_error;
  if (find_in_path("squeue").empty()) queue_error = "squeue not found in PATH";
  else try {
      states = task_states(arrays);
    } catch (const ComputeError& e) {
      queue_error = e.what();
    }
  std::vector<SlurmCaseState> out;
  for (const auto& k : c.cases) {
    SlurmCaseState s{k.id, "", "not submitted", ""};
    auto it = tasks.find(k.id);
    if (it != tasks.end()) {
      const TaskRecord& t = it->second;
      s.job = t.job;
      auto st = states.find(t.job);
      if (st != states.end() && active_state(st->second)) {
        std::string lower = st->second;
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char ch) { return std::tolower(ch); });
        s.state = lower;
      } else if (auto o = finished_outcome(c, k, t, 0)) {
        s.state = o->status;
        s.detail = o->message;
      } else if (!queue_error.empty()) {
        s.state = "unknown";
        s.detail = queue_error;
      } else {
        s.state = kLost;
        s.detail = lost_outcome(k, t, st == states.end() ? "left the queue" : st->second, 0).message;
      }
    }
    out.push_back(s);
  }
  return out;
}

CohortReport run_cohort_slurm(const CohortConfig& c, const CohortRunOptions& o_in, std::ostream& out) {
  // A dry run submits nothing, so it needs no sbatch; the script it shows is
  // the one a real run would submit (without --dry-run).
  CohortRunOptions o = o_in;
  o.run_args.erase(std::remove(o.run_args.begin(), o.run_args.end(), std::string("--dry-run")), o.run_args.end());
  if (!o.dry_run)
    for (const char* tool : {"sbatch", "squeue", "scancel", "scontrol"})
      if (find_in_path(tool).empty())
        throw ComputeError(fmt::format("{}: backend slurm: '{}' not found in PATH (install the Debian package "
                                       "slurm-client, or use backend: local / --backend local)",
                                       c.file.string(), tool));
  const auto case_files = materialize_cases(c);
  const std::vector<std::size_t> todo = selected_cases(c, o.only_cases);
  auto tasks = load_tasks(c);

  // What becomes of each selected case: attach to its queued/running task,
  // keep its finished up-to-date result, or submit it again.
  std::set<std::string> arrays;
  for (const std::size_t i : todo)
    if (auto it = tasks.find(c.cases[i].id); it != tasks.end()) arrays.insert(it->second.array);
  const bool can_query = !o.dry_run || !find_in_path("squeue").empty();
  if (!can_query && !arrays.empty())
    out << "dry run: squeue not found, so recorded tasks count as no longer queued\n";
  const auto states = can_query ? task_states(arrays) : std::map<std::string, std::string>{};
  const bool always = std::any_of(o.run_args.begin(), o.run_args.end(), [](const std::string& a) { return a == "--force"; });
  std::vector<std::size_t> attach, submit;
  std::vector<CaseOutcome> done;
  for (const std::size_t i : todo) {
    const auto& k = c.cases[i];
    auto it = tasks.find(k.id);
    if (it != tasks.end()) {
      auto st = states.find(it->second.job);
      if (st != states.end() && active_state(st->second)) {
        attach.push_back(i);
        continue;
      }
      if (!always && up_to_date(c, k, case_files[i], it->second, o.run_args)) {
        done.push_back(*finished_outcome(c, k, it->second, 0));
        continue;
      }
    }
    submit.push_back(i);
  }

  if (o.dry_run) {
    out << fmt::format("cohort {} (dry run, nothing is submitted): {} cases: {} to submit, {} queued or running, {} up to date\n",
                       c.name, todo.size(), submit.size(), attach.size(), done.size());
    for (const std::size_t i : attach) out << fmt::format("  {}: would attach to Slurm task {}\n", c.cases[i].id, tasks.at(c.cases[i].id).job);
    if (!submit.empty()) {
      std::vector<std::string> ids;
      for (const std::size_t i : submit) ids.push_back(c.cases[i].id);
      const fs::path sdir = c.work_dir / "slurm";
      std::string cmd = "sbatch";
      for (const auto& a : sbatch_array_arguments(c, ids.size(), sdir)) cmd += " " + sh_quote(a);
      out << fmt::format("would first submit a one-task probe job (can the compute nodes see {}?), then:\n", c.work_dir.string());
      out << "  " << cmd << " " << (sdir / "array-<time>-<pid>.sh").string() << "\n";
      out << "with this script (task i runs case i of the list):\n";
      std::istringstream script(slurm_array_script(c, ids, o.binary, o.run_args));
      for (std::string line; std::getline(script, line);) out << "  | " << line << "\n";
    }
    out.flush();
    CohortReport rep;
    rep.waited = false;
    return rep;
  }

  process::StopSignals signals;  // a Ctrl-C cancels what this run submitted

  struct Follow {
    std::size_t index;
    std::chrono::steady_clock::time_point since;
    std::optional<std::chrono::steady_clock::time_point> gone;  // first seen outside the queue without exit code
    std::optional<std::chrono::steady_clock::time_point> unreadable;  // first seen with its manifest unreadable
    bool finished = false;
  };
  std::vector<Follow> follow;
  const auto now = std::chrono::steady_clock::now();
  for (const std::size_t i : attach) follow.push_back({i, now, {}, {}});
  auto active_tasks = [&] {
    std::vector<std::string> ids;
    for (const auto& f : follow)
      if (!f.finished) ids.push_back(tasks.at(c.cases[f.index].id).job);
    return ids;
  };

  out << fmt::format("cohort {}: {} cases: {} to submit, {} queued or running (attached), {} up to date\n", c.name,
                     todo.size(), submit.size(), attach.size(), done.size());
  for (const std::size_t i : attach) out << fmt::format("  {}: attached to Slurm task {}\n", c.cases[i].id, tasks.at(c.cases[i].id).job);
  out.flush();

  std::string submitted_at;  // stages finished since then feed the ETA
  if (!attach.empty()) {
    // Attached tasks were submitted earlier: their stages count from then.
    for (const std::size_t i : attach) {
      const std::string s = tasks.at(c.cases[i].id).submitted;
      if (submitted_at.empty() || s < submitted_at) submitted_at = s;
    }
  }
  if (!submit.empty()) {
    if (submitted_at.empty()) submitted_at = utc_now();
    try {
      probe(c, o.binary, out);
      const fs::path sdir = c.work_dir / "slurm";
      std::vector<std::string> ids;
      for (const std::size_t i : submit) {
        ids.push_back(c.cases[i].id);
        fs::remove(c.work_dir / c.cases[i].id / "exit_code");
      }
      const fs::path script = sdir / fmt::format("array-{}-{}.sh", utc_now(), ::getpid());
      files::write_atomic(script, slurm_array_script(c, ids, o.binary, o.run_args));
      fs::permissions(script, fs::perms::owner_all | fs::perms::group_read | fs::perms::others_read);
      std::vector<std::string> argv = {"sbatch"};
      const auto args = sbatch_array_arguments(c, ids.size(), sdir);
      argv.insert(argv.end(), args.begin(), args.end());
      argv.push_back(script.string());
      const auto r = run_command(argv);
      const std::string job = trim(r.output).substr(0, trim(r.output).find(';'));
      if (r.code != 0 || job.empty() || job.find_first_not_of("0123456789") != std::string::npos)
        throw ComputeError(fmt::format("{}: sbatch of the job array ({} cases: {}{}) failed (exit {}): {}", c.file.string(),
                                       ids.size(), ids.front(), ids.size() > 1 ? ", ..." : "", r.code, trim(r.output)));
      const std::string when = utc_now();
      for (std::size_t t = 0; t < submit.size(); ++t) {
        TaskRecord rec{job + "_" + std::to_string(t), job, sdir / fmt::format("slurm-{}_{}.out", job, t), o.run_args, when};
        tasks[c.cases[submit[t]].id] = rec;
        follow.push_back({submit[t], std::chrono::steady_clock::now(), {}, {}});
      }
      save_tasks(c, tasks);
      out << fmt::format("submitted job array {} ({} task(s) of {} rank(s) x {} cpu(s)): {}\n", job, ids.size(),
                         c.ranks_per_case, c.slurm.cpus_per_case, script.string());
      out.flush();
    } catch (...) {
      if (!o.no_wait) cancel(active_tasks(), out);
      throw;
    }
  }

  CohortReport rep;
  if (o.no_wait && process::StopSignals::received()) {  // Ctrl-C while submitting: take back what was submitted
    cancel(active_tasks(), out);
    throw Interrupted();
  }
  if (o.no_wait) {
    rep.waited = false;
    out << fmt::format("not waiting (--no-wait): follow with `stentsim cohort status {}`\n", c.file.string());
    return rep;
  }

  // Wait: pending/running from squeue, done/failed from exit-code files and manifests.
  const std::size_t total = todo.size();
  const auto t0 = std::chrono::steady_clock::now();
  const std::string since = submitted_at.empty() ? utc_now() : submitted_at;
  // A task seen outside the queue without its exit-code file gets a grace period
  // (a shared file system may show the file late) before it counts as lost.
  const double grace = std::max(2.0, 3 * c.slurm.poll_interval_s);
  std::string last_line;
  try {
    // squeue failing for a while (the controller restarting, a network blip) is waited
    // out; only a long outage ends the follower, and then the tasks keep running.
    const double queue_patience = c.slurm.queue_patience_s;
    bool queue_failing = false;
    std::chrono::steady_clock::time_point queue_failing_since;
    while (!process::StopSignals::received() && std::any_of(follow.begin(), follow.end(), [](const Follow& f) { return !f.finished; })) {
      std::set<std::string> live;
      for (const auto& f : follow)
        if (!f.finished) live.insert(tasks.at(c.cases[f.index].id).array);
      std::map<std::string, std::string> st;
      try {
        st = task_states(live);
        if (queue_failing) out << "slurm: squeue answers again\n";
        queue_failing = false;
      } catch (const ComputeError& e) {
        const auto now = std::chrono::steady_clock::now();
        if (!queue_failing) {
          queue_failing = true;
          queue_failing_since = now;
          out << fmt::format("{}; trying again for up to {:.0f} s\n", e.what(), queue_patience);
          out.flush();
        }
        const double failing_s = std::chrono::duration<double>(now - queue_failing_since).count();
        if (failing_s >= queue_patience)
          throw QueueUnreachable(fmt::format("{} (for {:.0f} s); the submitted tasks were left to run: follow them with "
                                             "`stentsim cohort status {}`", e.what(), failing_s, c.file.string()));
        sleep_interruptibly(c.slurm.poll_interval_s);
        continue;
      }
      int pending = 0, running = 0;
      for (auto& f : follow) {
        if (f.finished) continue;
        const auto& k = c.cases[f.index];
        const TaskRecord& t = tasks.at(k.id);
        auto s = st.find(t.job);
        if (s != st.end() && active_state(s->second)) {
          (s->second == "PENDING" ? pending : running)++;
          continue;
        }
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - f.since).count();
        std::optional<CaseOutcome> r = finished_outcome(c, k, t, wall);
        if (r && !r->manifest_error.empty()) {
          // A manifest another node is still writing reads as damaged for a moment: the grace
          // period again before the case counts as failed.
          if (!f.unreadable) f.unreadable = std::chrono::steady_clock::now();
          if (std::chrono::duration<double>(std::chrono::steady_clock::now() - *f.unreadable).count() < grace) continue;
        }
        if (!r) {
          if (!f.gone) f.gone = std::chrono::steady_clock::now();
          if (std::chrono::duration<double>(std::chrono::steady_clock::now() - *f.gone).count() < grace) continue;
          r = lost_outcome(k, t, s == st.end() ? "left the queue" : s->second, wall);
        }
        f.finished = true;
        done.push_back(*r);
        const int unexpected = static_cast<int>(
            std::count_if(done.begin(), done.end(), [](const CaseOutcome& d) { return !d.as_expected(); }));
        out << fmt::format("[{}/{}] {:<20} {}{}  (task {}, {} unexpected, {:.0f} s elapsed)\n", done.size(), total, r->id,
                           r->status, r->failed_stage.empty() ? "" : " at " + r->failed_stage, t.job, unexpected,
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      // ETA from the median stage times so far (the cases' manifests, written
      // by `stentsim run` in each task), over the tasks running now.
      std::map<std::string, std::vector<double>> samples;
      std::vector<std::set<std::string>> unfinished;
      for (const auto& f : follow) {
        const auto stages = stages_finished_since(c.work_dir / c.cases[f.index].id / "work" / "manifest.yaml", since);
        if (f.finished)
          for (const auto& [stage, dt] : stages) samples[stage].push_back(dt);
        else {
          std::set<std::string> s;
          for (const auto& [stage, dt] : stages) s.insert(stage);
          unfinished.push_back(s);
        }
      }
      const auto eta = cohort_eta(samples, unfinished, std::max(1, running));
      const std::string line = fmt::format("slurm: {} pending, {} running, {}/{} finished, ETA {}", pending, running,
                                           done.size(), total, eta ? fmt::format("{:.0f} s", *eta) : std::string("-"));
      if (line != last_line && (pending + running) > 0) out << line << "\n";
      last_line = line;
      out.flush();
      if (std::any_of(follow.begin(), follow.end(), [](const Follow& f) { return !f.finished; }))
        sleep_interruptibly(c.slurm.poll_interval_s);
    }
  } catch (const QueueUnreachable& e) {
    throw ComputeError(e.what());  // scancel would not reach the controller either
  } catch (...) {
    cancel(active_tasks(), out);
    throw;
  }
  if (process::StopSignals::received()) {
    const auto ids = active_tasks();
    cancel(ids, out);
    // Wait (bounded) until the cancelled tasks have left the active states.
    std::set<std::string> live;
    for (const auto& f : follow)
      if (!f.finished) live.insert(tasks.at(c.cases[f.index].id).array);
    for (int i = 0; i < 100; ++i) {
      std::map<std::string, std::string> st;
      try {
        st = task_states(live);
      } catch (const ComputeError& e) {  // the queue is down: the cancel cannot be confirmed, the stop stands
        out << fmt::format("{}; the cancel of {} task(s) is not confirmed\n", e.what(), ids.size());
        break;
      }
      if (std::none_of(ids.begin(), ids.end(), [&](const std::string& id) {
            auto s = st.find(id);
            return s != st.end() && active_state(s->second);
          }))
        break;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    throw Interrupted();
  }
  rep.cases = done;
  sort_like_cohort(c, rep.cases);
  return rep;
}

}  // namespace stentsim::workflows
