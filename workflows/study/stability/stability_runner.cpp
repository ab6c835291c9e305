#include "workflows/study/stability/stability_runner.hpp"

#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <ostream>
#include <sstream>
#include <thread>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/markdown.hpp"
#include "common/summary.hpp"
#include "common/mesh_data.hpp"
#include "pipeline/manifest.hpp"
#include "workflows/study/input_paths.hpp"
#include "workflows/version.hpp"

namespace fs = std::filesystem;

namespace stentsim::study {
namespace {

std::string lower(std::string s) {
  for (auto& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

std::string shorten(const std::string& s, std::size_t n = 300) { return s.size() <= n ? s : s.substr(0, n - 3) + "..."; }

/// The log's message: the last line that reports an error or a failure, else
/// the last non-empty line.
std::string log_message(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last, last_error;
  while (std::getline(in, line)) {
    line = trim(line);
    if (line.empty()) continue;
    last = line;
    const std::string l = lower(line);
    if (l.find("error") != std::string::npos || l.find("fail") != std::string::npos) last_error = line;
  }
  return shorten(last_error.empty() ? last : last_error);
}

/// A text cell that is a non-finite number ("nan", ".nan", "-inf", ".inf").
bool non_finite_text(std::string t) {
  t = lower(trim(t));
  if (t.empty()) return false;
  if (t[0] == '+' || t[0] == '-') t.erase(0, 1);
  if (!t.empty() && t[0] == '.') t.erase(0, 1);
  return t == "nan" || t == "inf" || t == "infinity" || t.rfind("nan(", 0) == 0;
}

bool yaml_non_finite(const YAML::Node& n, std::string& where, const std::string& path) {
  if (n.IsScalar()) {
    if (non_finite_text(n.Scalar())) {
      where = path;
      return true;
    }
    return false;
  }
  if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i)
      if (yaml_non_finite(n[i], where, fmt::format("{}[{}]", path, i))) return true;
  } else if (n.IsMap()) {
    for (const auto& kv : n)
      if (yaml_non_finite(kv.second, where, path.empty() ? kv.first.as<std::string>() : path + "." + kv.first.as<std::string>()))
        return true;
  }
  return false;
}

std::string mesh_non_finite(const MeshData& m) {
  for (const auto& p : m.points)
    if (!p.allFinite()) return "point coordinates";
  for (const auto* data : {&m.point_data, &m.cell_data})
    for (const auto& [name, a] : *data)
      for (double v : a.values)
        if (!std::isfinite(v)) return fmt::format("{} data '{}'", data == &m.point_data ? "point" : "cell", name);
  return "";
}

std::optional<double> number_of(const YAML::Node& qoi, const std::string& name) {
  const YAML::Node v = qoi[name] ? qoi[name]["value"] : YAML::Node();
  if (!v || !v.IsScalar()) return std::nullopt;
  try {
    return v.as<double>();
  } catch (const YAML::Exception&) {
    return std::nullopt;
  }
}

std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch == '\n' ? ' ' : ch);
  return q + "\"";
}


std::string opt(const std::optional<double>& v) { return v ? fmt::format("{:g}", *v) : ""; }

fs::path summary_file(const StabilityCase& c, const fs::path& case_dir) {
  switch (c.kind) {
    case StabilityCase::Kind::scene: return case_dir / "out" / "summary.yaml";
    case StabilityCase::Kind::case_file: return case_dir / (c.input.stem().string() + ".work") / "solve" / "summary.yaml";
    case StabilityCase::Kind::exec: return case_dir / "summary.yaml";
  }
  return {};
}

}  // namespace

int StabilityReport::unexpected() const {
  return static_cast<int>(std::count_if(cases.begin(), cases.end(), [](const StabilityOutcome& o) { return !o.as_expected; }));
}

std::string find_non_finite(const fs::path& dir) {
  if (!fs::exists(dir)) return "";
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    const std::string ext = f.extension().string(), rel = f.lexically_relative(dir).string();
    try {
      if (f.filename() == "summary.yaml" || f.filename() == "manifest.yaml") {
        std::string where;
        if (yaml_non_finite(YAML::LoadFile(f.string()), where, "")) return fmt::format("{}: {}", rel, where);
      } else if (ext == ".csv") {
        std::ifstream in(f);
        std::string line;
        for (int row = 1; std::getline(in, line); ++row) {
          std::stringstream ss(line);
          for (std::string cell; std::getline(ss, cell, ',');)
            if (non_finite_text(cell)) return fmt::format("{}: row {}", rel, row);
        }
      } else if (ext == ".vtu" || ext == ".vtp") {
        const MeshData m = ext == ".vtu" ? read_vtu(f.string()) : read_vtp(f.string());
        if (auto w = mesh_non_finite(m); !w.empty()) return fmt::format("{}: {}", rel, w);
      }
    } catch (const std::exception& e) {
      // an unreadable output is not a NaN, but it is not clean either
      return fmt::format("{}: unreadable ({})", rel, shorten(e.what(), 120));
    }
  }
  return "";
}

StabilityOutcome classify_case(const StabilityCase& c, const ChildRun& run, const fs::path& case_dir, const fs::path& log) {
  StabilityOutcome o;
  o.id = c.id;
  o.run = run;
  // Counts and QoIs from the summary, whatever the outcome.
  const fs::path sf = summary_file(c, case_dir);
  std::string status, failure;
  if (fs::exists(sf)) {
    try {
      const YAML::Node root = YAML::LoadFile(sf.string());
      const YAML::Node q = root["qoi"];
      o.steps = number_of(q, "steps");
      o.iterations = number_of(q, "newton_iterations");
      o.cuts = number_of(q, "step_cuts");
      o.final_time = number_of(q, "final_time");
      if (q["status"] && q["status"]["value"]) status = q["status"]["value"].as<std::string>();
      if (root["notes"] && root["notes"]["failure"]) failure = root["notes"]["failure"].as<std::string>();
      for (const auto& kv : q) {
        const YAML::Node v = kv.second["value"];
        std::vector<double> vals;
        try {
          if (v.IsSequence()) vals = v.as<std::vector<double>>();
          else if (v.IsScalar()) vals = {v.as<double>()};
        } catch (const YAML::Exception&) {
          continue;  // text QoI
        }
        o.qois[kv.first.as<std::string>()] = vals;
      }
    } catch (const YAML::Exception&) {
      // an unreadable summary is found again by the NaN scan below
    }
  }

  if (run.timed_out) {
    o.outcome = "hang";
    o.message = fmt::format("still running after {:.0f} s: ended", run.wall_s);
    return o;
  }
  if (run.signal) {
    o.outcome = "crash";
    o.message = fmt::format("killed by signal {} ({})", run.signal, ::strsignal(run.signal));
    return o;
  }
  if (auto where = find_non_finite(case_dir); !where.empty()) {
    o.outcome = "nan";
    o.message = "non-finite value in " + where;
    return o;
  }
  if (run.exit_code == 0) {
    o.outcome = "converged";
    if (c.kind == StabilityCase::Kind::scene && status != "completed") {
      o.outcome = "failed uncleanly";
      o.message = fmt::format("exit 0 but {} says status '{}'", sf.filename().string(), status);
    }
    return o;
  }
  // A non-zero exit: clean only with a message and the last converged state.
  o.message = log_message(log);
  if (run.exit_code == 127 || run.exit_code == 126) {
    o.outcome = "failed uncleanly";
    return o;
  }
  if (c.kind != StabilityCase::Kind::exec && run.exit_code == 2) {
    // An input error: "rejected" when it says why (a case may expect it, e.g. a device
    // that starts inside the wall); unexpected everywhere else.
    o.outcome = o.message.empty() ? "failed uncleanly" : "rejected";
    o.message = "input rejected: " + o.message;
    if (o.outcome == "rejected" && !c.message.empty() && o.message.find(c.message) == std::string::npos) {
      o.outcome = "failed uncleanly";
      o.message += fmt::format(" (expected a message with '{}')", c.message);
    }
    return o;
  }
  switch (c.kind) {
    case StabilityCase::Kind::scene: {
      const bool state = status == "failed" && fs::exists(case_dir / "out" / "results.pvd");
      if (!failure.empty()) o.message = shorten(failure);
      o.outcome = state && !o.message.empty() ? "failed cleanly" : "failed uncleanly";
      if (!state) o.message = fmt::format("no last converged state (summary status '{}', results.pvd {}): {}", status,
                                          fs::exists(case_dir / "out" / "results.pvd") ? "present" : "missing", o.message);
      break;
    }
    case StabilityCase::Kind::case_file: {
      const fs::path manifest = case_dir / (c.input.stem().string() + ".work") / "manifest.yaml";
      std::string stage, stage_message;
      if (fs::exists(manifest)) {
        const auto m = pipeline::Manifest::load(manifest);
        for (const auto& name : {"segmentation", "centerline", "placement", "balloon", "stent", "mesh", "fibers", "solve", "report"})
          if (const auto* rec = m.find(name); rec && rec->status == "failed") {
            stage = name;
            stage_message = trim(rec->message);
            break;
          }
      }
      if (stage_message.find("killed by signal") != std::string::npos) {
        o.outcome = "crash";
        o.message = fmt::format("stage {}: {}", stage, stage_message);
        break;
      }
      if (!stage_message.empty()) o.message = shorten(fmt::format("stage {}: {}", stage, stage_message));
      o.outcome = !stage.empty() && !stage_message.empty() ? "failed cleanly" : "failed uncleanly";
      if (!c.failed_stage.empty() && stage != c.failed_stage)
        o.check = fmt::format("expected stage '{}' to fail, not '{}'", c.failed_stage, stage);
      break;
    }
    case StabilityCase::Kind::exec:
      o.outcome = o.message.empty() ? "failed uncleanly" : "failed cleanly";
      break;
  }
  return o;
}

namespace {

void check_expectations(const StabilityCase& c, StabilityOutcome& o, const std::vector<StabilityOutcome>& earlier) {
  std::vector<std::string> why;
  if (!o.check.empty()) why.push_back(o.check);
  if (std::find(c.expect.begin(), c.expect.end(), o.outcome) == c.expect.end()) {
    std::string list;
    for (const auto& e : c.expect) list += (list.empty() ? "" : " or ") + e;
    why.push_back(fmt::format("expected {}", list));
  }
  if (o.outcome == "failed cleanly" && !c.message.empty() && o.message.find(c.message) == std::string::npos)
    why.push_back(fmt::format("message lacks '{}'", c.message));
  if (c.compare) {
    const auto ref = std::find_if(earlier.begin(), earlier.end(), [&](const StabilityOutcome& e) { return e.id == c.compare->case_id; });
    if (ref == earlier.end()) {
      why.push_back(fmt::format("compare: case '{}' was not run", c.compare->case_id));
    } else if (!ref->qois.count(c.compare->qoi) || !o.qois.count(c.compare->qoi) ||
               ref->qois.at(c.compare->qoi).size() != o.qois.at(c.compare->qoi).size()) {
      why.push_back(fmt::format("compare: QoI '{}' missing in this case or in '{}'", c.compare->qoi, c.compare->case_id));
    } else {
      const auto& a = o.qois.at(c.compare->qoi);
      const auto& b = ref->qois.at(c.compare->qoi);
      double d = 0;
      for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
      if (!(d <= c.compare->tolerance))
        why.push_back(fmt::format("{} differs from {} by {:.3g} > {:.3g}", c.compare->qoi, c.compare->case_id, d, c.compare->tolerance));
      else o.message += (o.message.empty() ? "" : "; ") + fmt::format("{} within {:.3g} of {}", c.compare->qoi, d, c.compare->case_id);
    }
  }
  o.as_expected = why.empty();
  o.check.clear();
  for (const auto& w : why) o.check += (o.check.empty() ? "" : "; ") + w;
}

std::vector<std::string> command_of(const StabilityCase& c, const fs::path& input_copy, const fs::path& case_dir,
                                    const std::string& binary) {
  std::vector<std::string> argv;
  switch (c.kind) {
    case StabilityCase::Kind::scene:
      argv = {binary, "solve", input_copy.string(), "--out", (case_dir / "out").string()};
      break;
    case StabilityCase::Kind::case_file:
      argv = {binary, "run", input_copy.string()};
      if (!c.until.empty()) argv.insert(argv.end(), {"--until", c.until});
      break;
    case StabilityCase::Kind::exec:
      argv = c.exec;
      break;
  }
  argv.insert(argv.end(), c.args.begin(), c.args.end());
  return argv;
}

/// `value` with "{suite_dir}" in its texts replaced by the suite file's folder:
/// the case's input copy lives in its own folder, so a file beside the suite
/// (a mesh) is named through this.
YAML::Node with_suite_dir(const YAML::Node& value, const std::string& suite_dir) {
  YAML::Node v = YAML::Clone(value);
  if (v.IsScalar()) {
    std::string t = v.Scalar();
    for (std::size_t at; (at = t.find("{suite_dir}")) != std::string::npos;) t.replace(at, 11, suite_dir);
    if (t != v.Scalar()) v = YAML::Node(t);
  } else if (v.IsSequence()) {
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = with_suite_dir(v[i], suite_dir);
  } else if (v.IsMap()) {
    for (auto kv : v) kv.second = with_suite_dir(kv.second, suite_dir);
  }
  return v;
}

std::string host_line() {
  char host[256] = {0};
  ::gethostname(host, sizeof host - 1);
  double load[3] = {0, 0, 0};
  ::getloadavg(load, 3);
  return fmt::format("host {}, {} cores, load average {:.2f} {:.2f} {:.2f}, stentsim {}", host,
                     std::max(1u, std::thread::hardware_concurrency()), load[0], load[1], load[2], kVersion);
}

}  // namespace

StabilityReport run_stability_suite(const StabilitySuite& s, const StabilityOptions& o, std::ostream& out) {
  if (o.binary.empty() && std::any_of(s.cases.begin(), s.cases.end(), [](const auto& c) { return c.kind != StabilityCase::Kind::exec; }))
    throw InputError("stability: no stentsim executable given");
  for (const auto& id : o.only)
    if (std::none_of(s.cases.begin(), s.cases.end(), [&](const StabilityCase& c) { return c.id == id; }))
      throw InputError(fmt::format("{}: --cases names '{}', which is not a case of this suite", s.file.string(), id));
  std::vector<const StabilityCase*> todo;
  for (const auto& c : s.cases) {
    const bool chosen = o.only.empty() ? (o.subset == "all" || c.subset == "quick")
                                       : std::find(o.only.begin(), o.only.end(), c.id) != o.only.end();
    if (chosen) todo.push_back(&c);
  }
  fs::create_directories(o.out_dir);
  StabilityReport r;
  r.suite = s.name;
  out << fmt::format("stability suite '{}': {} case(s) ({}), in {}\n", s.name, todo.size(),
                     o.only.empty() ? "subset " + o.subset : "chosen", o.out_dir.string())
      << host_line() << "\n";
  for (std::size_t i = 0; i < todo.size(); ++i) {
    const StabilityCase& c = *todo[i];
    const fs::path dir = o.out_dir / c.id;
    fs::remove_all(dir);  // a case always runs from scratch: no cached stage may hide a failure
    fs::create_directories(dir);
    fs::path input_copy;
    if (c.kind != StabilityCase::Kind::exec) {
      YAML::Node root = YAML::LoadFile(c.input.string());
      // The copy runs in the case's folder: files the input names relative
      // to itself, and those the suite's values name relative to the suite,
      // are given by absolute path (workflows/study/input_paths.hpp).
      resolve_relative_files(root, fs::absolute(c.input).parent_path());
      const fs::path suite_dir = fs::absolute(s.file).parent_path();
      for (const auto& [key, value] : c.set) {
        YAML::Node v = with_suite_dir(value, suite_dir.string());
        resolve_relative_files(v, suite_dir);
        set_dotted_key(root, key, v);
      }
      YAML::Emitter em;
      em << root;
      input_copy = dir / c.input.filename();
      files::write_atomic(input_copy, std::string(em.c_str()) + "\n");
    }
    const double limit = s.limit_s(c);
    out << fmt::format("[{}/{}] {} (limit {:.0f} s) ... ", i + 1, todo.size(), c.id, limit) << std::flush;
    const fs::path log = dir / "log.txt";
    const ChildRun run = run_child(command_of(c, input_copy, dir, o.binary), dir, log, limit);
    StabilityOutcome oc = classify_case(c, run, dir, log);
    oc.limit_s = limit;
    check_expectations(c, oc, r.cases);
    out << fmt::format("{} in {:.1f} s", oc.outcome, run.wall_s);
    if (oc.iterations) out << fmt::format(" ({} steps, {} Newton iterations, {} cuts)", opt(oc.steps), opt(oc.iterations), opt(oc.cuts));
    out << (oc.as_expected ? "" : "  NOT AS EXPECTED: " + oc.check) << "\n";
    if (!oc.message.empty()) out << "    " << oc.message << "\n";
    r.cases.push_back(std::move(oc));
    write_stability_tables(r, o.out_dir);
  }
  out << fmt::format("{} of {} case(s) as expected; tables in {}\n", r.cases.size() - static_cast<std::size_t>(r.unexpected()),
                     r.cases.size(), (o.out_dir / "stability.md").string());
  return r;
}

void write_stability_tables(const StabilityReport& r, const fs::path& dir) {
  std::string csv =
      "case,outcome,as_expected,check,exit_code,signal,steps,newton_iterations,step_cuts,final_time,wall_time_s,limit_s,"
      "cpu_time_s,peak_memory_mb,message\n";
  for (const auto& o : r.cases)
    csv += fmt::format("{},{},{},{},{},{},{},{},{},{},{:.3f},{:.0f},{:.3f},{:.1f},{}\n", csv_cell(o.id), o.outcome,
                       o.as_expected ? "yes" : "no", csv_cell(o.check), o.run.exit_code, o.run.signal, opt(o.steps),
                       opt(o.iterations), opt(o.cuts), opt(o.final_time), o.run.wall_s, o.limit_s, o.run.cpu_s,
                       o.run.peak_memory_mb, csv_cell(o.message));
  files::write_atomic(dir / "stability.csv", csv);

  std::string md = fmt::format("# Stability suite: {}\n\n{}\n\n", r.suite, host_line());
  md += "| case | outcome | as expected | Newton iterations | step cuts | time (s) | limit (s) | message |\n";
  md += "|---|---|---|---:|---:|---:|---:|---|\n";
  for (const auto& o : r.cases)
    md += fmt::format("| {} | {} | {} | {} | {} | {:.1f} | {:.0f} | {} |\n", markdown_cell(o.id), o.outcome,
                      o.as_expected ? "yes" : "**no**: " + markdown_cell(o.check), opt(o.iterations), opt(o.cuts), o.run.wall_s,
                      o.limit_s, markdown_cell(o.message));
  md += fmt::format("\n{} of {} case(s) as expected.\n", r.cases.size() - static_cast<std::size_t>(r.unexpected()), r.cases.size());
  files::write_atomic(dir / "stability.md", md);
  stability_summary(r).write(dir / "summary.yaml");
}

Summary stability_summary(const StabilityReport& r) {
  Summary sum;
  sum.set("cases_total", static_cast<double>(r.cases.size()));
  sum.set("cases_as_expected", static_cast<double>(r.cases.size()) - r.unexpected());
  sum.set("cases_not_as_expected", static_cast<double>(r.unexpected()));
  // Every outcome class, zeros included, so a reader never has to guess
  // whether a missing count means none.
  for (const char* outcome : {"converged", "failed cleanly", "rejected", "failed uncleanly", "hang", "crash", "nan"}) {
    std::string name = std::string("cases_") + outcome;
    std::replace(name.begin(), name.end(), ' ', '_');
    sum.set(name, static_cast<double>(std::count_if(r.cases.begin(), r.cases.end(),
                                                    [&](const StabilityOutcome& o) { return o.outcome == outcome; })));
  }
  double child_wall = 0, child_mem = 0;
  for (const auto& o : r.cases) {
    child_wall += o.run.wall_s;
    child_mem = std::max(child_mem, o.run.peak_memory_mb);
  }
  sum.set("cases_wall_time_total", child_wall, "s");
  sum.set("case_peak_memory_max", child_mem, "MB");
  sum.note("suite", r.suite);
  // wall_time_s / peak_memory_mb: this process (the runner), set by Summary.
  return sum;
}

}  // namespace stentsim::study
