#include "workflows/cohort/cohort_runner.hpp"

#include <fmt/format.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <map>
#include <ostream>
#include <set>
#include <thread>

#include "common/child_process.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/stop_signals.hpp"
#include "common/summary.hpp"
#include "pipeline/manifest.hpp"
#include "workflows/case_stages.hpp"
#include "workflows/cohort/cohort_plots.hpp"

namespace fs = std::filesystem;

namespace stentsim::workflows {
namespace {

// What a failed run's log says went wrong: its last "error: " line (the runner's own,
// naming the stage and its error), without the prefix; else the log's last lines.
std::string failure_message(const fs::path& log) {
  std::ifstream in(log);
  std::string line, error;
  while (std::getline(in, line))
    if (line.rfind("error: ", 0) == 0) error = line.substr(7);
  return error.empty() ? files::log_tail(log, 3) : error;
}

// The first failed stage in the case's manifest, or none.
std::optional<pipeline::StageRecord> failed_record(const fs::path& manifest_file, std::string& stage) {
  stage.clear();
  if (!fs::exists(manifest_file)) return std::nullopt;
  const auto m = pipeline::Manifest::load(manifest_file);
  for (const auto& name : all_stage_names())
    if (auto* r = m.find(name); r && r->status != "ok") {
      stage = name;
      return *r;
    }
  return std::nullopt;
}

// The error kind of a case's `stentsim run` from its exit status and the failed stage's record.
std::string error_kind_of(int exit_code, const std::optional<pipeline::StageRecord>& failed) {
  if (exit_code == 0) return "";
  if (exit_code == 130) return "interrupted";
  if (exit_code > 128) return "crash";  // the worker itself was killed
  if (failed) return pipeline::to_string(failed->error_kind);
  return exit_code == 2 ? "input" : "compute";  // refused before any stage ran: the case file, the work folder
}

bool stage_succeeded(const fs::path& manifest_file, const std::string& stage) {
  if (!fs::exists(manifest_file)) return false;  // throws on a file-system error (case_outcome catches it)
  const auto m = pipeline::Manifest::load(manifest_file);
  const auto* rec = m.find(stage);
  return rec && rec->status == "ok";
}

// A case's `stentsim run`, one thread per library (the cohort's cores go to
// parallel cases). It sits in a process group of its own and dies with the
// pool (PR_SET_PDEATHSIG: its runner stops its stage and keeps earlier
// artifacts), so a killed `cohort run` leaves no orphans.
pid_t start_case(const std::string& binary, const fs::path& case_file, const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv = {binary, "run", case_file.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  process::ChildSetup setup;
  setup.log = log;
  setup.env = process::single_thread_environment();
  return process::spawn_exec(argv, setup);
}

const char* const kStartup = "(case start-up)";

/// Case keys that hold a file path (as cohort_config.cpp absolutizes them):
/// the summary shows their file name.
bool is_path_key(const std::string& dotted) {
  const std::string last = dotted.substr(dotted.rfind('.') == std::string::npos ? 0 : dotted.rfind('.') + 1);
  return last == "file" || last == "lumen" || last == "wall" || last == "path" || last == "image";
}

/// A YAML node flattened to dotted keys ("mesh.generic.elements_around" ->
/// "16"); sequences as flow YAML, a null (a removed key) as "null".
void flatten(const YAML::Node& n, const std::string& prefix, std::vector<std::pair<std::string, std::string>>& out) {
  if (n.IsMap()) {
    for (const auto& kv : n) flatten(kv.second, prefix.empty() ? kv.first.Scalar() : prefix + "." + kv.first.Scalar(), out);
  } else if (n.IsScalar()) {
    out.emplace_back(prefix, is_path_key(prefix) ? fs::path(n.Scalar()).filename().string() : n.Scalar());
  } else if (n.IsNull()) {
    out.emplace_back(prefix, "null");
  } else {
    YAML::Emitter e;
    e << YAML::Flow << n;
    out.emplace_back(prefix, e.c_str());
  }
}

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
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
  const fs::path manifest = dir / "work" / "manifest.yaml";
  // The manifest is read only where it decides something: which stage failed, or
  // whether the stage meant to fail ran. An interrupted run's may be an earlier run's.
  // An unreadable one (damaged, a permission, a shared file system that shows a rewrite
  // half done) is this case's failure, never the pool's: the other cases go on.
  std::optional<pipeline::StageRecord> failed;
  bool expected_stage_ran = false;
  try {
    if (r.exit_code && r.exit_code != 130) failed = failed_record(manifest, r.failed_stage);
    else if (r.exit_code == 0 && k.expect_failure) expected_stage_ran = stage_succeeded(manifest, *k.expect_failure);
  } catch (const std::exception& e) {
    r.manifest_error = e.what();  // names the file
  }
  r.error_kind = error_kind_of(r.exit_code, failed);
  if (!r.manifest_error.empty()) {
    r.status = "failed";
    // A crash or a refused case file (exit 2, a damaged manifest among them) is known from
    // the exit status alone; which stage failed, or whether the expected one ran, is not.
    if (r.exit_code == 0 || (r.exit_code != 2 && r.exit_code <= 128)) r.error_kind = "unknown";
    r.message = r.exit_code == 0 ? fmt::format("the run succeeded but whether stage {} ran is unknown: {}", *k.expect_failure,
                                               r.manifest_error)
                                 : r.manifest_error;
  } else if (r.exit_code == 0)
    // With --until/--only the stage meant to fail may not have run: then "done".
    r.status = expected_stage_ran ? "succeeded unexpectedly" : "done";
  else if (r.exit_code == 130) r.status = "interrupted";  // before the manifest, which may be an earlier run's
  else if (k.expect_failure && r.failed_stage == *k.expect_failure) r.status = "failed as expected";
  else r.status = "failed";
  if (r.exit_code) {
    const std::string log = failure_message(dir / "run.log");
    r.message = r.message.empty() ? log : log.empty() ? r.message : r.message + "; log: " + log;
  }
  if (r.exit_code > 128 && r.exit_code != 130)  // the worker itself was killed: its log cannot say so
    r.message = fmt::format("stentsim run killed by signal {} ({}){}", r.exit_code - 128, strsignal(r.exit_code - 128),
                            r.message.empty() ? "" : "; log: " + r.message);
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

std::vector<std::string> stages_in_progress(const fs::path& case_work_dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& name : all_stage_names())
    if (fs::is_directory(case_work_dir / ".tmp" / name, ec)) out.push_back(name);
  return out;
}

CaseActivity case_activity(const fs::path& case_work_dir) {
  CaseActivity a;
  const fs::path lock = case_work_dir / ".lock";
  struct stat st {};
  if (::stat(lock.c_str(), &st) != 0) return a;
  // /proc/locks lines: "1: FLOCK  ADVISORY  WRITE 1234 fe:00:10953002 0 EOF"
  // (device major:minor in hex, inode in decimal); "->" lines are waiters.
  const std::string dev = fmt::format("{:02x}:{:02x}:{}", major(st.st_dev), minor(st.st_dev), st.st_ino);
  std::ifstream locks("/proc/locks");
  for (std::string line; std::getline(locks, line);) {
    std::istringstream in(line);
    std::string num, kind, mode, access, pid, where;
    if (!(in >> num >> kind) || kind == "->") continue;
    if (in >> mode >> access >> pid >> where && kind == "FLOCK" && where == dev) {
      a.running = true;
      break;
    }
  }
  if (!a.running) return a;
  a.holder = files::read_text(lock);
  while (!a.holder.empty() && (a.holder.back() == '\n' || a.holder.back() == ' ')) a.holder.pop_back();
  a.stages = stages_in_progress(case_work_dir);
  return a;
}

std::optional<double> cohort_eta(const std::map<std::string, std::vector<double>>& samples,
                                 const std::vector<std::set<std::string>>& finished, int parallel) {
  if (samples.empty()) return std::nullopt;
  std::map<std::string, double> median;
  for (const auto& [stage, v] : samples)
    if (!v.empty()) median[stage] = median_of(v);
  if (median.empty()) return std::nullopt;
  double work = 0;
  for (const auto& done : finished)
    for (const auto& [stage, m] : median)
      if (!done.count(stage)) work += m;
  return work / std::max(1, parallel);
}

std::map<std::string, double> stages_finished_since(const fs::path& manifest_file, const std::string& since) {
  std::map<std::string, double> out;
  std::error_code ec;
  if (!fs::exists(manifest_file, ec)) return out;
  pipeline::Manifest m;
  try {
    m = pipeline::Manifest::load(manifest_file);
  } catch (const std::exception&) {
    return out;  // for the ETA only; being rewritten elsewhere (a Slurm task on another node): next time
  }
  for (const auto& [name, rec] : m.stages())
    if (rec.status == "ok" && rec.finished >= since) out[name] = rec.duration_s;  // ISO 8601 UTC sorts as text
  return out;
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
  std::map<std::string, std::vector<double>> stage_samples;  // stage -> durations in this cohort run
  const std::string since = pipeline::utc_now_iso8601();
  const auto t0 = std::chrono::steady_clock::now();
  auto manifest_of = [&](std::size_t i) { return c.work_dir / c.cases[i].id / "work" / "manifest.yaml"; };

  std::size_t next = 0;
  bool stopping = false;
  {
    // Signals blocked except while the pool sleeps: a stop can fall neither
    // between the flag's check and the sleep nor between a fork and the
    // registration of its worker.
    process::StopSignals signals(process::StopSignals::Mode::wait_for_signal);
    try {
      while (true) {
        while (!process::StopSignals::received() && next < todo.size() && static_cast<int>(running.size()) < slots) {
          const std::size_t i = todo[next++];
          const fs::path dir = c.work_dir / c.cases[i].id;
          const pid_t pid = start_case(o.binary, case_files[i], o.run_args, dir / "run.log");
          running[pid] = {i, std::chrono::steady_clock::now()};  // still blocked: no signal in between
        }
        if (running.empty()) break;
        if (process::StopSignals::received() && !stopping) {
          stopping = true;
          out << fmt::format("stopping: {} running case(s) get SIGTERM (their runners keep finished stages)\n", running.size());
          out.flush();
          for (auto& [p, r] : running) ::kill(-p, SIGTERM);  // the worker's group
        }
        const auto reaped = process::poll_any();
        if (!reaped) {
          signals.wait();  // a worker's end or a stop; a signal sent before this line is pending and wakes it
          continue;
        }
        const pid_t pid = reaped->pid;
        const int status = reaped->wait_status;
        auto it = running.find(pid);
        if (it == running.end()) continue;
        int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        // Ended by the pool's own SIGTERM before its runner caught it (still starting up): interrupted
        // (what the progress line says; a stopped pool writes no summary).
        if (stopping && WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) code = 130;
        CaseOutcome r = case_outcome(c, c.cases[it->second.index], code,
                                     std::chrono::duration<double>(std::chrono::steady_clock::now() - it->second.start).count());
        double stage_sum = 0;
        for (const auto& [stage, dt] : stages_finished_since(manifest_of(it->second.index), since)) {
          stage_samples[stage].push_back(dt);
          stage_sum += dt;
        }
        // What a case costs besides its stages (start-up, planning, hashing):
        // counted like a stage that a running case has already paid.
        stage_samples[kStartup].push_back(std::max(0.0, r.wall_s - stage_sum));
        running.erase(it);
        done.push_back(r);
        // ETA: what the unfinished cases still need, at the median stage times so far.
        std::vector<std::set<std::string>> finished;
        for (const auto& [p, rr] : running) {
          std::set<std::string> s = {kStartup};
          for (const auto& [stage, dt] : stages_finished_since(manifest_of(rr.index), since)) s.insert(stage);
          finished.push_back(s);
        }
        for (std::size_t k = next; k < todo.size(); ++k) finished.emplace_back();
        const auto eta = cohort_eta(stage_samples, finished, slots);
        const int failed = static_cast<int>(std::count_if(done.begin(), done.end(), [](const CaseOutcome& d) { return !d.as_expected(); }));
        out << fmt::format("[{}/{}] {:<20} {}{}  ({} unexpected, {:.0f} s elapsed, ETA {})\n", done.size(), todo.size(), r.id,
                           r.status, r.failed_stage.empty() ? "" : " at " + r.failed_stage, failed,
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                           eta ? fmt::format("{:.0f} s", *eta) : std::string("-"));
        out.flush();
      }
    } catch (...) {
      // The pool cannot go on (a worker that could not start, an output error): its
      // workers stop with it rather than writing cases nobody follows.
      std::vector<pid_t> pids;
      for (const auto& [p, r] : running) pids.push_back(p);
      process::stop_and_reap(pids);
      throw;
    }
  }
  CohortReport rep;
  rep.cases = done;
  sort_like_cohort(c, rep.cases);
  if (process::StopSignals::received()) throw Interrupted();
  return rep;
}

const std::vector<std::string>& cohort_fixed_columns() {
  static const std::vector<std::string> columns = {"case", "status", "exit_code", "failed_stage", "error_kind",
                                                   "message", "wall_time_s", "inputs"};
  return columns;
}

CohortTable cohort_table(const CohortConfig& c, const CohortReport& r) {
  // Columns: fixed ones, then "<stage>.<qoi>" for every QoI any case has.
  CohortTable t;
  std::set<std::string> columns, override_columns;
  for (const auto& o : r.cases) {
    auto k = std::find_if(c.cases.begin(), c.cases.end(), [&](const CohortCase& cc) { return cc.id == o.id; });
    std::map<std::string, std::string> row = {{"case", o.id},
                                              {"status", o.status},
                                              {"exit_code", o.exit_code >= 0 ? std::to_string(o.exit_code) : std::string()},
                                              {"failed_stage", o.failed_stage},
                                              {"error_kind", o.error_kind},
                                              {"message", o.message},
                                              {"wall_time_s", fmt::format("{:.3f}", o.wall_s)}};
    if (k != c.cases.end()) {
      // Inputs: the merged case's input section (files by name), then the case's own overrides.
      std::vector<std::pair<std::string, std::string>> in, ov;
      flatten(merged_case(c, *k)["input"], "", in);
      std::string inputs;
      for (const auto& [key, v] : in) inputs += (inputs.empty() ? "" : "; ") + key + "=" + v;
      row["inputs"] = inputs;
      flatten(k->overrides, "", ov);
      for (const auto& [key, v] : ov) {
        row["override." + key] = v;
        override_columns.insert("override." + key);
      }
    }
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
  t.columns = cohort_fixed_columns();
  t.columns.insert(t.columns.end(), override_columns.begin(), override_columns.end());
  t.columns.insert(t.columns.end(), columns.begin(), columns.end());
  return t;
}

namespace {

// The cells of one CSV line as write_cohort_summary writes it (every cell quoted, "" for a quote).
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quoted && ch == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      cur += '"';
      ++i;
    } else if (ch == '"') quoted = !quoted;
    else if (ch == ',' && !quoted) {
      out.push_back(cur);
      cur.clear();
    } else cur += ch;
  }
  out.push_back(cur);
  return out;
}

}  // namespace

void add_unselected_cases(const CohortConfig& c, CohortReport& r) {
  // The previous summary's rows: case id -> column -> cell.
  std::map<std::string, std::map<std::string, std::string>> previous;
  const fs::path csv = c.work_dir / "cohort_summary.csv";
  if (fs::exists(csv)) {
    std::istringstream in(files::read_text(csv));
    std::string line;
    std::getline(in, line);
    const auto header = csv_fields(line);
    while (std::getline(in, line)) {
      const auto cells = csv_fields(line);
      std::map<std::string, std::string> row;
      for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
      if (!row["case"].empty()) previous[row["case"]] = row;
    }
  }
  for (const auto& k : c.cases) {
    if (std::any_of(r.cases.begin(), r.cases.end(), [&](const CaseOutcome& o) { return o.id == k.id; })) continue;
    CaseOutcome o;
    o.id = k.id;
    if (auto p = previous.find(k.id); p != previous.end() && !p->second["status"].empty()) {
      auto& row = p->second;
      o.status = row["status"];
      o.exit_code = row["exit_code"].empty() ? -1 : std::atoi(row["exit_code"].c_str());
      o.failed_stage = row["failed_stage"];
      o.error_kind = row["error_kind"];
      o.message = row["message"];
      o.wall_s = std::atof(row["wall_time_s"].c_str());
    } else {
      const fs::path manifest = c.work_dir / k.id / "work" / "manifest.yaml";
      if (!fs::exists(manifest)) {
        o.status = "not run";
        o.exit_code = -1;
      } else {
        std::optional<pipeline::StageRecord> failed;
        try {
          failed = failed_record(manifest, o.failed_stage);
        } catch (const std::exception& e) {  // this case's row says so; the summary is still written
          o.failed_stage.clear();
          o.status = "failed";
          o.exit_code = -1;
          o.error_kind = "unknown";
          o.message = e.what();
          r.cases.push_back(o);
          continue;
        }
        if (failed) o.error_kind = pipeline::to_string(failed->error_kind);
        if (o.failed_stage.empty()) o.status = "done";
        else {
          o.status = k.expect_failure && *k.expect_failure == o.failed_stage ? "failed as expected" : "failed";
          o.exit_code = -1;  // not known from the manifest
          o.message = failure_message(c.work_dir / k.id / "run.log");
        }
      }
    }
    r.cases.push_back(o);
  }
  sort_like_cohort(c, r.cases);
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
