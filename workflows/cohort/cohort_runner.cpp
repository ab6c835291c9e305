#include "workflows/cohort/cohort_runner.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <fstream>
#include <map>
#include <ostream>
#include <set>
#include <thread>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/summary.hpp"
#include "pipeline/manifest.hpp"
#include "workflows/case_stages.hpp"
#include "workflows/cohort/cohort_plots.hpp"

namespace fs = std::filesystem;

namespace stentsim::workflows {
namespace {

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_cohort_stop(int sig) { g_stop = sig; }

std::string tail_lines(const fs::path& file, int n) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  std::string out;
  for (std::size_t i = lines.size() > static_cast<std::size_t>(n) ? lines.size() - static_cast<std::size_t>(n) : 0; i < lines.size(); ++i)
    out += (out.empty() ? "" : " | ") + lines[i];
  return out;
}

std::string failed_stage_of(const fs::path& manifest_file) {
  if (!fs::exists(manifest_file)) return "";
  const auto m = pipeline::Manifest::load(manifest_file);
  for (const auto& name : all_stage_names())
    if (auto* r = m.find(name); r && r->status != "ok") return name;
  return "";
}

bool stage_succeeded(const fs::path& manifest_file, const std::string& stage) {
  if (!fs::exists(manifest_file)) return false;
  const auto m = pipeline::Manifest::load(manifest_file);
  const auto* rec = m.find(stage);
  return rec && rec->status == "ok";
}

pid_t start_case(const std::string& binary, const fs::path& case_file, const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv_s = {binary, "run", case_file.string()};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  fs::create_directories(log.parent_path());
  pid_t pid = ::fork();
  if (pid < 0) throw ComputeError("cohort: fork failed");
  if (pid == 0) {
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      ::close(fd);
    }
    // One thread per library inside a cohort: cases already use every core.
    ::setenv("OMP_NUM_THREADS", "1", 1);
    std::vector<char*> argv;
    for (auto& s : argv_s) argv.push_back(s.data());
    argv.push_back(nullptr);
    ::execv(binary.c_str(), argv.data());
    std::perror("cohort: exec of stentsim failed");
    ::_exit(127);
  }
  return pid;
}

}  // namespace

int CohortReport::unexpected() const {
  return static_cast<int>(std::count_if(cases.begin(), cases.end(), [](const CaseOutcome& c) { return !c.as_expected(); }));
}

CaseOutcome case_outcome(const CohortConfig& c, const CohortCase& k, int exit_code, double wall_s) {
  const fs::path dir = c.work_dir / k.id;
  CaseOutcome r;
  r.id = k.id;
  r.wall_s = wall_s;
  r.exit_code = exit_code;
  r.failed_stage = r.exit_code ? failed_stage_of(dir / "work" / "manifest.yaml") : "";
  if (r.exit_code == 0)
    // With --until/--only the stage meant to fail may not have run: then "done".
    r.status = k.expect_failure && stage_succeeded(dir / "work" / "manifest.yaml", *k.expect_failure) ? "succeeded unexpectedly" : "done";
  else if (k.expect_failure && r.failed_stage == *k.expect_failure) r.status = "failed as expected";
  else r.status = r.exit_code == 130 ? "interrupted" : "failed";
  if (r.exit_code) r.message = tail_lines(dir / "run.log", 3);
  return r;
}

void sort_like_cohort(const CohortConfig& c, std::vector<CaseOutcome>& cases) {
  auto pos = [&](const std::string& id) {
    return std::find_if(c.cases.begin(), c.cases.end(), [&](const CohortCase& k) { return k.id == id; }) - c.cases.begin();
  };
  std::stable_sort(cases.begin(), cases.end(), [&](const CaseOutcome& a, const CaseOutcome& b) { return pos(a.id) < pos(b.id); });
}

std::vector<std::size_t> selected_cases(const CohortConfig& c, const std::vector<std::string>& only) {
  for (const auto& id : only)
    if (std::none_of(c.cases.begin(), c.cases.end(), [&](const CohortCase& k) { return k.id == id; }))
      throw InputError(fmt::format("{}: --cases names '{}', which is not a case of this cohort", c.file.string(), id));
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < c.cases.size(); ++i)
    if (only.empty() || std::count(only.begin(), only.end(), c.cases[i].id)) todo.push_back(i);
  return todo;
}

int concurrent_cases(int workers, int ranks_per_case, int cores) {
  return std::max(1, std::min(workers, cores / std::max(1, ranks_per_case)));
}

CohortReport run_cohort(const CohortConfig& c, const CohortRunOptions& o, std::ostream& out) {
  const auto case_files = materialize_cases(c);
  const std::vector<std::size_t> todo = selected_cases(c, o.only_cases);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int workers = o.workers > 0 ? o.workers : c.workers > 0 ? c.workers : cores;
  const int slots = concurrent_cases(workers, c.ranks_per_case, cores);
  out << fmt::format("cohort {}: {} cases, {} at once ({} workers, {} ranks per case, {} cores)\n", c.name, todo.size(),
                     slots, workers, c.ranks_per_case, cores);

  struct Running {
    std::size_t index;
    std::chrono::steady_clock::time_point start;
  };
  std::map<pid_t, Running> running;
  std::vector<CaseOutcome> done;  // in completion order
  std::vector<double> durations;
  const auto t0 = std::chrono::steady_clock::now();
  struct sigaction sa {}, old_int {}, old_term {};
  sa.sa_handler = on_cohort_stop;
  sigemptyset(&sa.sa_mask);
  g_stop = 0;
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);

  std::size_t next = 0;
  while (next < todo.size() || !running.empty()) {
    while (!g_stop && next < todo.size() && static_cast<int>(running.size()) < slots) {
      const std::size_t i = todo[next++];
      const fs::path dir = c.work_dir / c.cases[i].id;
      pid_t pid = start_case(o.binary, case_files[i], o.run_args, dir / "run.log");
      running[pid] = {i, std::chrono::steady_clock::now()};
    }
    if (running.empty()) break;
    int status = 0;
    pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR && g_stop)
        for (auto& [p, r] : running) ::kill(p, SIGTERM);
      continue;
    }
    auto it = running.find(pid);
    if (it == running.end()) continue;
    CaseOutcome r = case_outcome(c, c.cases[it->second.index], WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status),
                                 std::chrono::duration<double>(std::chrono::steady_clock::now() - it->second.start).count());
    running.erase(it);
    durations.push_back(r.wall_s);
    done.push_back(r);
    const std::size_t n_done = done.size();
    std::vector<double> sorted = durations;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted[sorted.size() / 2];
    const double eta = median * static_cast<double>(todo.size() - n_done) / slots;
    const int failed = static_cast<int>(std::count_if(done.begin(), done.end(), [](const CaseOutcome& d) { return !d.as_expected(); }));
    out << fmt::format("[{}/{}] {:<20} {}{}  ({} unexpected, {:.0f} s elapsed, ETA {:.0f} s)\n", n_done, todo.size(), r.id,
                       r.status, r.failed_stage.empty() ? "" : " at " + r.failed_stage, failed,
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), eta);
    out.flush();
  }
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  CohortReport rep;
  rep.cases = done;
  sort_like_cohort(c, rep.cases);
  if (g_stop) throw Interrupted();
  return rep;
}

CohortTable cohort_table(const CohortConfig& c, const CohortReport& r) {
  // Columns: fixed ones, then "<stage>.<qoi>" for every QoI any case has.
  CohortTable t;
  std::set<std::string> columns;
  for (const auto& o : r.cases) {
    std::map<std::string, std::string> row = {{"case", o.id}, {"status", o.status}, {"failed_stage", o.failed_stage},
                                              {"message", o.message}, {"wall_time_s", fmt::format("{:.3f}", o.wall_s)}};
    for (const auto& stage : all_stage_names()) {
      const fs::path f = c.work_dir / o.id / "work" / stage / "summary.yaml";
      if (!fs::exists(f)) continue;
      const Summary s = Summary::read(f);
      for (const auto& [name, q] : s.qois()) {
        std::string v;
        if (auto d = std::get_if<double>(&q.value)) v = fmt::format("{:.12g}", *d);
        else if (auto txt = std::get_if<std::string>(&q.value)) v = *txt;
        else continue;  // vectors do not fit a CSV cell
        const std::string col = stage + "." + name + (q.unit.empty() ? "" : " [" + q.unit + "]");
        row[col] = v;
        columns.insert(col);
      }
      row[stage + ".wall_time_s"] = fmt::format("{:.3f}", s.wall_time_s());
      columns.insert(stage + ".wall_time_s");
    }
    t.rows.push_back(std::move(row));
  }
  t.columns = {"case", "status", "failed_stage", "message", "wall_time_s"};
  t.columns.insert(t.columns.end(), columns.begin(), columns.end());
  return t;
}

void write_cohort_summary(const CohortConfig& c, const CohortReport& r) {
  const CohortTable t = cohort_table(c, r);
  auto quote = [](const std::string& s) {
    std::string q = "\"";
    for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return q + "\"";
  };
  std::string text;
  for (std::size_t i = 0; i < t.columns.size(); ++i) text += (i ? "," : "") + quote(t.columns[i]);
  text += "\n";
  for (const auto& row : t.rows) {
    for (std::size_t i = 0; i < t.columns.size(); ++i) {
      auto it = row.find(t.columns[i]);
      text += (i ? "," : "") + quote(it == row.end() ? "" : it->second);
    }
    text += "\n";
  }
  files::write_atomic(c.work_dir / "cohort_summary.csv", text);
  write_cohort_markdown(c, t);
  write_cohort_plots(c, t);
}

}  // namespace stentsim::workflows
