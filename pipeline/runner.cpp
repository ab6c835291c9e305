#include "pipeline/runner.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <map>
#include <ostream>
#include <set>

#include "common/child_process.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/stop_signals.hpp"
#include "pipeline/stage_process.hpp"
#include "pipeline/staleness.hpp"
#include "pipeline/work_lock.hpp"

namespace fs = std::filesystem;

namespace stentsim::pipeline {
namespace {

struct Running {
  std::size_t stage;
  StageChild child;
  std::chrono::steady_clock::time_point start;
  fs::path temp_dir;
  // Taken before the stage starts: an input edited while it runs must leave
  // the stage stale, not be recorded as the content its outputs came from.
  std::map<std::string, std::string> input_hashes;
};

std::string join_reasons(const std::vector<std::string>& r) { return fmt::format("{}", fmt::join(r, "; ")); }

}  // namespace

const char* to_string(StageState s) {
  switch (s) {
    case StageState::up_to_date: return "up to date";
    case StageState::stale: return "stale";
    case StageState::failed: return "failed";
    case StageState::never_run: return "not run";
  }
  return "";
}

Runner::Runner(Plan plan, std::string tool_version) : plan_(std::move(plan)), tool_version_(std::move(tool_version)) {}

std::vector<StageStatus> Runner::status() const {
  const Manifest manifest = Manifest::load(manifest_file());
  std::vector<StageStatus> out(plan_.stages().size());
  std::vector<bool> will_change(plan_.stages().size(), false);
  for (std::size_t i : plan_.order()) {
    const Stage& s = plan_.stages()[i];
    StageStatus st{s.name, StageState::up_to_date, {}, {}};
    if (const StageRecord* r = manifest.find(s.name)) st.record = *r;
    st.reasons = stale_reasons(plan_, i, manifest);
    for (std::size_t u : plan_.upstream(i))
      if (will_change[u]) st.reasons.push_back(fmt::format("upstream stage {} is not up to date", plan_.stages()[u].name));
    if (!st.record) st.state = StageState::never_run;
    else if (st.record->status != "ok") st.state = StageState::failed;
    else if (!st.reasons.empty()) st.state = StageState::stale;
    will_change[i] = !st.reasons.empty();
    out[i] = std::move(st);
  }
  return out;
}

std::set<std::size_t> Runner::selection(const RunOptions& o) const {
  if (o.until && o.only) throw InputError("--until and --only cannot be combined");
  if (o.only) return {plan_.index(*o.only)};
  if (o.until) return plan_.with_ancestors(plan_.index(*o.until));
  std::set<std::size_t> all;
  for (std::size_t i = 0; i < plan_.stages().size(); ++i) all.insert(i);
  return all;
}

RunReport Runner::run(const RunOptions& options, std::ostream& out) {
  for (const auto& f : options.force) plan_.index(f);  // unknown names are errors
  const std::set<std::size_t> selected = selection(options);
  const auto& stages = plan_.stages();
  RunReport report;

  if (options.dry_run) {
    const auto st = status();
    out << fmt::format("plan for {} ({} stages selected):\n", plan_.work_dir().string(), selected.size());
    for (std::size_t i : plan_.order()) {
      if (!selected.count(i)) continue;
      auto reasons = st[i].reasons;
      if (options.force_all || options.force.count(stages[i].name)) reasons.insert(reasons.begin(), "forced");
      if (reasons.empty()) out << fmt::format("  skip  {:<13} up to date\n", stages[i].name);
      else out << fmt::format("  run   {:<13} {}\n", stages[i].name, join_reasons(reasons));
    }
    return report;
  }

  WorkLock lock(plan_.work_dir());
  if (!lock.stale_holder().empty())
    out << fmt::format("note: a previous run ({}) ended without finishing; its lock is stale and was taken over\n",
                       lock.stale_holder());
  Manifest manifest = Manifest::load(manifest_file());
  manifest.tool_version = tool_version_;

  // With --only, the stage's upstream outputs must already exist.
  if (options.only) {
    const std::size_t i = *selected.begin();
    for (std::size_t u : plan_.upstream(i))
      for (const auto& o : plan_.outputs(u))
        if (!fs::exists(plan_.work_dir() / o))
          throw InputError(fmt::format("--only {}: its input {} from stage {} does not exist yet; run without --only first",
                                       stages[i].name, o, stages[u].name));
  }

  // A stop ends the stages with SIGTERM and keeps what finished; signals stay
  // blocked outside the waits, so none falls between the flag's check and the wait.
  process::StopSignals signals(process::StopSignals::Mode::wait_for_signal);
  std::set<std::size_t> done, blocked;
  std::map<pid_t, Running> running;
  const int jobs = std::max(1, options.jobs);
  std::size_t counter = 0;
  const std::size_t total = selected.size();
  bool failing = false;
  std::set<std::size_t> unusable;  // failed, or needing a failed stage (keep_going)

  auto ready = [&](std::size_t i) {
    for (std::size_t u : plan_.upstream(i))
      if (selected.count(u) && !done.count(u)) return false;
    return true;
  };

  auto finish_child = [&](pid_t pid, int wstatus, const rusage& ru) {
    Running r = running.at(pid);
    running.erase(pid);
    const Stage& s = stages[r.stage];
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - r.start).count();
    StageOutcome o = collect_stage(r.child, wstatus, static_cast<double>(ru.ru_maxrss) / 1024.0, dt);
    if (o.ok) {
      // All outputs must exist before any is renamed, so a stage that wrote
      // only some of them never replaces earlier artifacts.
      for (const auto& declared : plan_.outputs(r.stage))
        if (!fs::exists(r.temp_dir / declared)) {
          o.ok = false;
          o.error_kind = ErrorKind::compute;
          o.message = fmt::format("did not write its declared output {}", declared);
          break;
        }
    }
    if (o.ok) {
      // Rename outputs into place, then record: a crash in between leaves a
      // manifest whose output hashes differ, so the stage simply runs again.
      for (const auto& declared : plan_.outputs(r.stage)) {
        fs::path target = plan_.work_dir() / declared;
        fs::create_directories(target.parent_path());
        files::replace(r.temp_dir / declared, target);
      }
    }
    // A failed stage's partial outputs (a solve's last converged frame, its
    // history) are moved to failed/<stage>/ for the user; nothing in place is
    // touched. A finished run of the stage replaces what an earlier one kept.
    const fs::path kept = plan_.work_dir() / "failed" / s.name;
    bool kept_partial = false;
    if (!o.interrupted && !process::StopSignals::received()) {
      std::error_code ec;
      fs::remove_all(kept, ec);
      if (!o.ok && fs::exists(r.temp_dir) && !fs::is_empty(r.temp_dir)) {
        fs::create_directories(kept.parent_path(), ec);
        fs::rename(r.temp_dir, kept, ec);
        kept_partial = !ec;
      }
    }
    fs::remove_all(r.temp_dir);
    StageRecord rec;
    rec.version = s.version;
    rec.config_hash = files::text_hash(s.config);
    rec.inputs = r.input_hashes;
    rec.finished = utc_now_iso8601();
    rec.duration_s = dt;
    rec.peak_memory_mb = o.peak_memory_mb;
    if (o.ok) {
      rec.status = "ok";
      rec.outputs = hash_outputs(plan_, r.stage);
      manifest.set(s.name, rec);
      manifest.save(manifest_file());
      std::error_code ec;
      fs::remove_all(resume_dir(plan_.work_dir(), s.name), ec);  // done: nothing left to resume
      fs::remove(plan_.work_dir() / ".resume", ec);               // only if empty
      done.insert(r.stage);
      report.ran.push_back(s.name);
      out << fmt::format("  done  {:<13} {:.2f} s, {:.0f} MB\n", s.name, dt, o.peak_memory_mb);
    } else if (o.interrupted || process::StopSignals::received()) {
      report.interrupted = true;
      out << fmt::format("  stop  {:<13} interrupted; earlier artifacts kept\n", s.name);
    } else {
      rec.status = "failed";
      rec.message = o.message;
      rec.error_kind = o.error_kind;
      manifest.set(s.name, rec);
      manifest.save(manifest_file());
      report.failed.push_back(s.name);
      if (report.first_failure.empty()) {
        report.first_failure = fmt::format("{}: {}", s.name, o.message);
        report.first_failure_kind = o.error_kind;
      }
      failing = !options.keep_going;
      unusable.insert(r.stage);
      out << fmt::format("  FAIL  {:<13} {}{}\n", s.name, o.error_kind == ErrorKind::input ? "bad input: " : "", o.message);
      out << fmt::format("        log: {}\n", (plan_.work_dir() / "logs" / (s.name + ".log")).string());
      if (kept_partial) out << fmt::format("        partial outputs: {}\n", kept.string());
    }
    out.flush();
  };

  std::vector<std::size_t> pending;
  for (std::size_t i : plan_.order())
    if (selected.count(i)) pending.push_back(i);

  while (true) {
    // Launch every ready stage while there is room and no stop or failure.
    for (auto it = pending.begin(); !failing && !process::StopSignals::received() && it != pending.end() && static_cast<int>(running.size()) < jobs;) {
      const std::size_t i = *it;
      const auto& up = plan_.upstream(i);
      const auto bad = std::find_if(up.begin(), up.end(), [&](std::size_t u) { return unusable.count(u) > 0; });
      if (bad != up.end()) {  // keep_going: what needs a failed stage cannot run
        it = pending.erase(it);
        unusable.insert(i);
        ++counter;
        report.blocked.push_back(stages[i].name);
        out << fmt::format("[{}/{}] skip  {:<13} needs {}, which failed\n", counter, total, stages[i].name, stages[*bad].name);
        it = pending.begin();
        continue;
      }
      if (!ready(i)) {
        ++it;
        continue;
      }
      it = pending.erase(it);
      const Stage& s = stages[i];
      ++counter;
      auto reasons = stale_reasons(plan_, i, manifest);
      if (options.force_all || options.force.count(s.name)) {
        reasons.insert(reasons.begin(), "forced");
        // Forced: from the beginning, not from what an earlier attempt left to resume.
        std::error_code ec;
        if (!options.dry_run) fs::remove_all(resume_dir(plan_.work_dir(), s.name), ec);
      }
      if (reasons.empty()) {
        done.insert(i);
        report.skipped.push_back(s.name);
        out << fmt::format("[{}/{}] skip  {:<13} up to date\n", counter, total, s.name);
        it = pending.begin();
        continue;
      }
      out << fmt::format("[{}/{}] run   {:<13} ({})\n", counter, total, s.name, join_reasons(reasons));
      out.flush();
      const fs::path temp_dir = plan_.work_dir() / ".tmp" / s.name;
      fs::remove_all(temp_dir);
      fs::create_directories(temp_dir);
      auto input_hashes = hash_inputs(plan_, i);
      StageChild child = start_stage(s, plan_.work_dir(), temp_dir, plan_.work_dir() / "logs" / (s.name + ".log"));
      running[child.pid] = Running{i, child, std::chrono::steady_clock::now(), temp_dir, std::move(input_hashes)};
      it = pending.begin();
    }
    if (running.empty()) break;
    if (process::StopSignals::received())
      for (const auto& [p, r] : running) ::kill(-p, SIGTERM);  // the stage's process group
    const auto reaped = process::poll_any();
    if (!reaped) {
      signals.wait();  // a stage's end or a stop signal (then the loop forwards it)
      continue;
    }
    const pid_t pid = reaped->pid;
    const int wstatus = reaped->wait_status;
    const rusage ru = reaped->usage;
    if (!running.count(pid)) continue;
    const std::string finished_name = stages[running.at(pid).stage].name;
    try {
      finish_child(pid, wstatus, ru);
    } catch (const std::exception& e) {
      // Recording failed (disk full, rename refused): stop the other stages
      // before reporting, so nothing writes the case after the lock is gone.
      std::vector<pid_t> pids;
      for (const auto& [p, r] : running) pids.push_back(p);
      process::stop_and_reap(pids);
      throw ComputeError(fmt::format("stage {}: {}", finished_name, e.what()));
    }
  }
  if (process::StopSignals::received()) report.interrupted = true;
  std::error_code ec;
  fs::remove(plan_.work_dir() / ".tmp", ec);  // only if empty
  return report;
}

}  // namespace stentsim::pipeline
