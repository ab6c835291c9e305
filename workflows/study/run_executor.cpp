#include "workflows/study/run_executor.hpp"

#include <fmt/format.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <ostream>
#include <thread>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/summary.hpp"
#include "common/child_process.hpp"
#include "common/stop_signals.hpp"
#include "workflows/version.hpp"

namespace fs = std::filesystem;

namespace stentsim::study {
namespace {

pid_t start_child(const std::vector<std::string>& args, const fs::path& log) {
  process::ChildSetup setup;
  setup.log = log;
  setup.append_log = true;  // the run's commands share run.log
  // One thread per rank: the core budget counts ranks.
  setup.env = process::single_thread_environment();
  setup.env.insert(setup.env.end(), {{"OMPI_ALLOW_RUN_AS_ROOT", "1"}, {"OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1"}});
  return process::spawn_exec(args, setup);
}

void write_result(const fs::path& file, const RunResult& r) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "status" << YAML::Value << r.status;
  e << YAML::Key << "message" << YAML::Value << r.message;
  e << YAML::Key << "wall_time_s" << YAML::Value << r.wall_s;
  e << YAML::Key << "cpu_time_s" << YAML::Value << r.cpu_s;
  e << YAML::Key << "peak_memory_mb" << YAML::Value << r.peak_memory_mb;
  e << YAML::Key << "peak_memory_rule" << YAML::Value << r.peak_memory_rule;
  e << YAML::Key << "host" << YAML::Value << r.host;
  e << YAML::Key << "nproc" << YAML::Value << r.nproc;
  e << YAML::Key << "load_average" << YAML::Value << r.load_average;
  e << YAML::Key << "binary_version" << YAML::Value << r.version;
  e << YAML::Key << "qoi" << YAML::Value << YAML::BeginMap;
  for (const auto& [name, v] : r.qoi) {
    e << YAML::Key << name << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (double x : v) e << x;
    e << YAML::EndSeq;
  }
  e << YAML::EndMap << YAML::EndMap;
  files::write_atomic(file, std::string(e.c_str()) + "\n");
}

void read_qois(const fs::path& summary, RunResult& r) {
  const Summary s = Summary::read(summary);
  for (const auto& [name, q] : s.qois()) {
    if (const auto* d = std::get_if<double>(&q.value)) r.qoi[name] = {*d};
    else if (const auto* v = std::get_if<std::vector<double>>(&q.value)) r.qoi[name] = *v;
    else if (const auto* t = std::get_if<std::string>(&q.value); t && name == "status" && *t != "completed") {
      r.status = "failed";
      if (r.message.empty()) r.message = "summary.yaml status: " + *t;
    }
  }
}

}  // namespace

void apply_rank_memory(RunResult& r, int ranks) {
  if (ranks <= 1) return;  // one process: wait4's peak is the run's
  const auto it = r.qoi.find(kPerRankMemoryQoi);
  if (it == r.qoi.end() || static_cast<int>(it->second.size()) != ranks) {
    r.peak_memory_rule = fmt::format("wait4: largest of {} ranks (the command reports no {})", ranks, kPerRankMemoryQoi);
    return;
  }
  double sum = 0;
  for (double m : it->second) sum += m;
  // The ranks' peaks need not coincide in time: the sum is an upper bound of
  // the run's peak, and what the run needs of a machine's memory.
  r.peak_memory_mb = std::max(r.peak_memory_mb, sum);
  r.peak_memory_rule = fmt::format("sum over {} ranks", ranks);
}

fs::path run_dir(const fs::path& out_dir, const RunSpec& run) { return out_dir / "runs" / run.key; }

HostInfo this_host(const std::string& binary) {
  HostInfo h;
  char name[256] = {};
  ::gethostname(name, sizeof name - 1);
  h.host = name;
  h.nproc = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  // The version string alone does not change between builds; the binary's
  // content does, and a changed solver must not reuse old timings or errors.
  h.version = fmt::format("{}+{}", kVersion, files::content_hash(binary).substr(0, 12));
  return h;
}

std::optional<RunResult> cached_result(const fs::path& dir, const HostInfo& host, bool reuse_timings) {
  const fs::path file = dir / "result.yaml";
  if (!fs::exists(file)) return std::nullopt;
  try {
    const YAML::Node n = YAML::LoadFile(file.string());
    RunResult r;
    r.status = n["status"].as<std::string>();
    r.message = n["message"].as<std::string>("");
    r.wall_s = n["wall_time_s"].as<double>();
    r.cpu_s = n["cpu_time_s"].as<double>();
    r.peak_memory_mb = n["peak_memory_mb"].as<double>();
    r.peak_memory_rule = n["peak_memory_rule"].as<std::string>("wait4");
    r.host = n["host"].as<std::string>();
    r.nproc = n["nproc"].as<int>();
    r.load_average = n["load_average"].as<double>();
    r.version = n["binary_version"].as<std::string>();
    for (const auto& kv : n["qoi"]) r.qoi[kv.first.as<std::string>()] = kv.second.as<std::vector<double>>();
    r.cached = true;
    if (r.status != "ok") return std::nullopt;
    if (!reuse_timings && (r.host != host.host || r.version != host.version)) return std::nullopt;
    return r;
  } catch (const YAML::Exception&) {
    return std::nullopt;  // unreadable: run again
  }
}

ExecStats execute_runs(const StudyConfig& study, const StudyPlan& plan, const fs::path& out_dir, const ExecOptions& o,
                       std::vector<RunResult>& results) {
  const HostInfo host = this_host(o.binary);
  const int cores = o.cores > 0 ? o.cores : host.nproc;
  const int jobs = std::max(1, o.jobs);
  results.assign(plan.runs.size(), RunResult{});
  ExecStats stats;
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < plan.runs.size(); ++i) {
    if (plan.runs[i].ranks > cores)
      throw InputError(fmt::format("{}: run '{}' needs {} MPI ranks but this machine has {} cores; timed runs never share cores",
                                   study.file.string(), plan.runs[i].label, plan.runs[i].ranks, cores));
    if (auto c = cached_result(run_dir(out_dir, plan.runs[i]), host, o.reuse_timings)) {
      results[i] = *c;
      ++stats.cached;
    } else {
      todo.push_back(i);
    }
  }
  if (todo.empty()) return stats;

  struct Running {
    std::size_t run;
    std::size_t command = 0;
    std::vector<std::vector<std::string>> commands;
    std::chrono::steady_clock::time_point start;
    double cpu = 0, peak = 0;
  };
  std::map<pid_t, Running> running;
  int ranks_in_flight = 0;
  std::size_t next = 0;

  // A stop ends the running runs (SIGTERM to their groups); finished runs keep their
  // results. Signals stay blocked outside the waits: none falls between the flag's check
  // and the wait.
  process::StopSignals signals(process::StopSignals::Mode::wait_for_signal);

  auto finish = [&](Running& r, bool ok, const std::string& why) {
    const RunSpec& spec = plan.runs[r.run];
    const fs::path dir = run_dir(out_dir, spec);
    RunResult& res = results[r.run];
    res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - r.start).count();
    res.cpu_s = r.cpu;
    res.peak_memory_mb = r.peak;
    res.status = ok ? "ok" : "failed";
    res.message = why;
    res.peak_memory_rule = "wait4";
    if (ok) {
      try {
        read_qois(dir / "summary.yaml", res);
      } catch (const std::exception& e) {
        res.status = "failed";
        res.message = fmt::format("no readable summary.yaml: {}", e.what());
      }
      apply_rank_memory(res, spec.ranks);
    }
    write_result(dir / "result.yaml", res);
    ++stats.executed;
    if (res.status != "ok") ++stats.failed;
    ranks_in_flight -= spec.ranks;
    if (o.out)
      *o.out << fmt::format("  {} {} ({:.2f} s){}\n", res.status == "ok" ? "done  " : "FAILED", spec.label, res.wall_s,
                            res.status == "ok" ? "" : ": " + res.message)
             << std::flush;
  };

  try {
    while (next < todo.size() || !running.empty()) {
      if (process::StopSignals::received()) throw Interrupted();
      // Start runs while a slot and enough cores are free (in plan order:
      // a big run waits for cores rather than being overtaken forever).
      while (next < todo.size() && static_cast<int>(running.size()) < jobs &&
             ranks_in_flight + plan.runs[todo[next]].ranks <= cores) {
        const std::size_t i = todo[next++];
        const RunSpec& spec = plan.runs[i];
        const fs::path dir = run_dir(out_dir, spec);
        fs::remove_all(dir);
        fs::create_directories(dir);
        files::write_atomic(dir / study.base_name, spec.input_text);
        Running r{i, 0, run_commands(study, spec, dir, o.binary), std::chrono::steady_clock::now(), 0, 0};
        RunResult& res = results[i];
        res = RunResult{};
        res.host = host.host;
        res.nproc = host.nproc;
        res.version = host.version;
        double load[1] = {0};
        if (::getloadavg(load, 1) == 1) res.load_average = load[0];
        ranks_in_flight += spec.ranks;
        stats.max_ranks_in_flight = std::max(stats.max_ranks_in_flight, ranks_in_flight);
        if (o.out) *o.out << fmt::format("  start  {} ({} rank{})\n", spec.label, spec.ranks, spec.ranks > 1 ? "s" : "") << std::flush;
        const pid_t pid = start_child(r.commands[0], dir / "run.log");
        running.emplace(pid, std::move(r));
      }
      if (running.empty()) continue;
      const auto reaped = process::poll_any();
      if (!reaped) {
        signals.wait();  // a run's end or a stop signal (the loop checks the flag)
        continue;
      }
      auto it = running.find(reaped->pid);
      if (it == running.end()) continue;
      Running& r = it->second;
      const process::ChildEnd end = process::child_end(reaped->wait_status, reaped->usage, 0);
      // wait4's rusage covers the child and its reaped descendants (mpirun's ranks):
      // CPU time is their sum, ru_maxrss the largest single process.
      r.cpu += end.cpu_s;
      r.peak = std::max(r.peak, end.peak_memory_mb);
      const fs::path dir = run_dir(out_dir, plan.runs[r.run]);
      const bool ok = end.ok();
      if (ok && r.command + 1 < r.commands.size()) {
        ++r.command;
        Running moved = std::move(r);
        running.erase(it);
        const pid_t next_pid = start_child(moved.commands[moved.command], dir / "run.log");
        running.emplace(next_pid, std::move(moved));
        continue;
      }
      std::string why;
      if (!ok) {
        why = end.describe();
        const std::string tail = files::log_tail(dir / "run.log", 2);
        if (!tail.empty()) why += ": " + tail;
      }
      Running done = std::move(r);
      running.erase(it);
      finish(done, ok, why);
    }
  } catch (...) {
    // A stop (Interrupted) or an error: the running runs get SIGTERM (each `stentsim run`
    // stops its stage and keeps what finished) and SIGKILL only if one is still running
    // after stop_and_reap's grace.
    std::vector<pid_t> pids;
    for (const auto& [pid, r] : running) pids.push_back(pid);
    process::stop_and_reap(pids);
    throw;
  }
  return stats;
}

}  // namespace stentsim::study
