#include "workflows/cohort/cohort_slurm.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <cstdlib>
#include <fstream>
#include <map>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>

#include "common/error.hpp"
#include "common/files.hpp"

namespace fs = std::filesystem;

namespace stentsim::workflows {
namespace {

volatile std::sig_atomic_t g_slurm_stop = 0;
extern "C" void on_slurm_stop(int sig) { g_slurm_stop = sig; }

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

// Runs a program (no shell) and captures its output.
CommandResult run_command(const std::vector<std::string>& argv_s) {
  int fds[2];
  if (::pipe(fds) != 0) throw ComputeError("cohort (slurm): pipe failed");
  const pid_t pid = ::fork();
  if (pid < 0) throw ComputeError("cohort (slurm): fork failed");
  if (pid == 0) {
    ::signal(SIGINT, SIG_IGN);  // the parent decides what a Ctrl-C cancels
    ::dup2(fds[1], 1);
    ::dup2(fds[1], 2);
    ::close(fds[0]);
    ::close(fds[1]);
    std::vector<char*> argv;
    for (auto s : argv_s) argv.push_back(::strdup(s.c_str()));
    argv.push_back(nullptr);
    ::execvp(argv[0], argv.data());
    std::perror(argv_s[0].c_str());
    ::_exit(127);
  }
  ::close(fds[1]);
  CommandResult r;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n > 0) r.output.append(buf, static_cast<std::size_t>(n));
    else if (n < 0 && errno == EINTR) continue;
    else break;
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '\r')) s.pop_back();
  return s;
}

std::string tail_of(const fs::path& file, int n) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::string out;
  const std::size_t from = lines.size() > static_cast<std::size_t>(n) ? lines.size() - static_cast<std::size_t>(n) : 0;
  for (std::size_t i = from; i < lines.size(); ++i) out += (out.empty() ? "" : " | ") + lines[i];
  return out;
}

// States in which a job still holds (or waits for) resources.
bool active_state(const std::string& s) {
  static const std::set<std::string> active = {"PENDING", "CONFIGURING", "RUNNING", "COMPLETING", "SUSPENDED",
                                               "REQUEUED", "REQUEUE_HOLD", "REQUEUE_FED", "RESIZING", "SIGNALING",
                                               "STAGE_OUT", "STOPPED"};
  return active.count(s) > 0;
}

// Job id -> state for the given jobs; a job missing from the map has left the queue.
std::map<std::string, std::string> job_states(const std::vector<std::string>& ids) {
  std::map<std::string, std::string> states;
  if (ids.empty()) return states;
  std::string list;
  for (const auto& id : ids) list += (list.empty() ? "" : ",") + id;
  const auto r = run_command({"squeue", "-h", "-t", "all", "-j", list, "-o", "%i %T"});
  if (r.code != 0) {
    // squeue rejects a list in which every job has been purged already.
    if (r.output.find("Invalid job id") != std::string::npos) return states;
    throw ComputeError("cohort (slurm): squeue failed (exit " + std::to_string(r.code) + "): " + trim(r.output));
  }
  std::istringstream in(r.output);
  for (std::string id, state; in >> id >> state;) states[id] = state;
  return states;
}

void cancel(const std::vector<std::string>& ids, std::ostream& out) {
  if (ids.empty()) return;
  std::vector<std::string> argv = {"scancel"};
  argv.insert(argv.end(), ids.begin(), ids.end());
  const auto r = run_command(argv);
  out << fmt::format("cancelled {} Slurm job(s){}\n", ids.size(), r.code ? ": scancel said " + trim(r.output) : "");
}

void sleep_interruptibly(double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!g_slurm_stop && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

}  // namespace

std::string slurm_batch_script(const CohortConfig& c, const CohortCase& k, const std::string& binary,
                               const fs::path& case_file, const std::vector<std::string>& run_args) {
  const fs::path dir = c.work_dir / k.id;
  std::string cmd = sh_quote(binary) + " run " + sh_quote(case_file.string());
  for (const auto& a : run_args) cmd += " " + sh_quote(a);
  // The exit code file is written atomically (temp + rename) as the job's
  // last act: its absence after the job left the queue means the job was lost.
  return fmt::format(
      "#!/bin/bash\n"
      "# generated by stentsim cohort (slurm back-end) for case '{}' of {}; do not edit\n"
      "export OMP_NUM_THREADS=1\n"
      "cd {} || exit 2\n"
      "{} > {} 2>&1\n"
      "rc=$?\n"
      "echo $rc > {} && mv -f {} {}\n"
      "exit $rc\n",
      k.id, c.file.string(), sh_quote(dir.string()), cmd, sh_quote((dir / "run.log").string()),
      sh_quote((dir / ".exit_code.tmp").string()), sh_quote((dir / ".exit_code.tmp").string()),
      sh_quote((dir / "exit_code").string()));
}

std::vector<std::string> sbatch_arguments(const CohortConfig& c, const CohortCase& k) {
  const fs::path dir = c.work_dir / k.id;
  std::vector<std::string> a = {"--parsable",
                                "--job-name=stentsim-" + c.name + "-" + k.id,
                                "--output=" + (dir / "slurm-%j.out").string(),
                                "--chdir=" + dir.string(),
                                "--ntasks=" + std::to_string(c.ranks_per_case),
                                "--cpus-per-task=" + std::to_string(c.slurm.cpus_per_case)};
  if (!c.slurm.partition.empty()) a.push_back("--partition=" + c.slurm.partition);
  if (!c.slurm.time_limit.empty()) a.push_back("--time=" + c.slurm.time_limit);
  if (!c.slurm.memory.empty()) a.push_back("--mem=" + c.slurm.memory);
  a.insert(a.end(), c.slurm.extra_options.begin(), c.slurm.extra_options.end());
  return a;
}

CohortReport run_cohort_slurm(const CohortConfig& c, const CohortRunOptions& o, std::ostream& out) {
  for (const char* tool : {"sbatch", "squeue", "scancel"})
    if (find_in_path(tool).empty())
      throw ComputeError(fmt::format("{}: backend slurm: '{}' not found in PATH (install the Debian package "
                                     "slurm-client, or use backend: local / --backend local)",
                                     c.file.string(), tool));
  const auto case_files = materialize_cases(c);
  const std::vector<std::size_t> todo = selected_cases(c, o.only_cases);

  struct Job {
    std::size_t index;
    std::string id;  // Slurm job id
    std::chrono::steady_clock::time_point submitted;
    bool finished = false;
  };
  std::vector<Job> jobs;
  auto active_ids = [&] {
    std::vector<std::string> ids;
    for (const auto& j : jobs)
      if (!j.finished) ids.push_back(j.id);
    return ids;
  };

  struct sigaction sa {}, old_int {}, old_term {};
  sa.sa_handler = on_slurm_stop;
  sigemptyset(&sa.sa_mask);
  g_slurm_stop = 0;
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  auto restore = [&] {
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
  };

  std::string job_list;
  try {
    for (const std::size_t i : todo) {
      if (g_slurm_stop) break;
      const auto& k = c.cases[i];
      const fs::path dir = c.work_dir / k.id;
      fs::remove(dir / "exit_code");
      const fs::path script = dir / "slurm_job.sh";
      files::write_atomic(script, slurm_batch_script(c, k, o.binary, case_files[i], o.run_args));
      fs::permissions(script, fs::perms::owner_all | fs::perms::group_read | fs::perms::others_read);
      std::vector<std::string> argv = {"sbatch"};
      const auto args = sbatch_arguments(c, k);
      argv.insert(argv.end(), args.begin(), args.end());
      argv.push_back(script.string());
      const auto r = run_command(argv);
      const std::string id = trim(r.output).substr(0, trim(r.output).find(';'));
      if (r.code != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
        throw ComputeError(fmt::format("{}: case '{}': sbatch failed (exit {}): {}", c.file.string(), k.id, r.code,
                                       trim(r.output)));
      jobs.push_back({i, id, std::chrono::steady_clock::now()});
      job_list += k.id + " " + id + "\n";
    }
    files::write_atomic(c.work_dir / "slurm_jobs.txt", job_list);
  } catch (...) {
    cancel(active_ids(), out);
    restore();
    throw;
  }
  out << fmt::format("cohort {}: {} cases submitted to Slurm ({} task(s) x {} cpu(s) each)\n", c.name, jobs.size(),
                     c.ranks_per_case, c.slurm.cpus_per_case);
  out.flush();

  std::vector<CaseOutcome> done;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    while (!g_slurm_stop && done.size() < jobs.size()) {
      const auto states = job_states(active_ids());
      for (auto& j : jobs) {
        if (j.finished) continue;
        auto st = states.find(j.id);
        if (st != states.end() && active_state(st->second)) continue;
        j.finished = true;
        const auto& k = c.cases[j.index];
        const fs::path dir = c.work_dir / k.id;
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - j.submitted).count();
        CaseOutcome r;
        std::ifstream ec(dir / "exit_code");
        int code = 0;
        if (ec >> code) {
          r = case_outcome(c, k, code, wall);
        } else {
          const std::string state = st == states.end() ? "left the queue" : st->second;
          r.id = k.id;
          r.wall_s = wall;
          r.exit_code = 1;
          r.status = "failed";
          r.message = fmt::format("lost (Slurm job {} {}: time, memory or node): {}", j.id, state,
                                  tail_of(dir / fmt::format("slurm-{}.out", j.id), 3));
        }
        done.push_back(r);
        const int unexpected = static_cast<int>(
            std::count_if(done.begin(), done.end(), [](const CaseOutcome& d) { return !d.as_expected(); }));
        out << fmt::format("[{}/{}] {:<20} {}{}  (job {}, {} unexpected, {:.0f} s elapsed)\n", done.size(), jobs.size(),
                           r.id, r.status, r.failed_stage.empty() ? "" : " at " + r.failed_stage, j.id, unexpected,
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        out.flush();
      }
      if (done.size() < jobs.size()) sleep_interruptibly(c.slurm.poll_interval_s);
    }
  } catch (...) {
    cancel(active_ids(), out);
    restore();
    throw;
  }
  if (g_slurm_stop) {
    const auto ids = active_ids();
    cancel(ids, out);
    // Wait (bounded) until the cancelled jobs have left the active states.
    for (int i = 0; i < 100; ++i) {
      const auto states = job_states(ids);
      if (std::none_of(states.begin(), states.end(), [](const auto& s) { return active_state(s.second); })) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    restore();
    throw Interrupted();
  }
  restore();
  CohortReport rep;
  rep.cases = done;
  sort_like_cohort(c, rep.cases);
  return rep;
}

}  // namespace stentsim::workflows
