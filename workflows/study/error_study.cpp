#include "workflows/study/error_study.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <ostream>

#include "common/error.hpp"
#include "workflows/study/analytic_references.hpp"
#include "workflows/study/study_config.hpp"

namespace fs = std::filesystem;

namespace stentsim::study {

double estimate_seconds(const StudyConfig& s, const StudyPlan& plan, std::size_t run,
                        const std::vector<std::optional<double>>& measured) {
  if (measured[run]) return *measured[run];
  int best_diff = std::numeric_limits<int>::max();
  double best = -1;
  const auto& a = plan.runs[run].setting;
  for (std::size_t j = 0; j < plan.runs.size(); ++j) {
    if (!measured[j]) continue;
    const auto& b = plan.runs[j].setting;
    int diff = 0;
    double scale = 1;
    for (const auto& k : s.knobs) {
      auto ia = a.find(k.name), ib = b.find(k.name);
      const int va = ia == a.end() ? -1 : ia->second, vb = ib == b.end() ? -1 : ib->second;
      if (va == vb) continue;
      ++diff;
      if (k.cost_exponent > 0 && va >= 0 && vb >= 0)
        scale *= std::pow(k.h[static_cast<std::size_t>(vb)] / k.h[static_cast<std::size_t>(va)], k.cost_exponent);
    }
    if (diff < best_diff) {
      best_diff = diff;
      best = *measured[j] * scale;
    }
  }
  return best;
}

Summary error_study_summary(const StudyConfig& study, const ErrorStudyResult& r) {
  Summary sum;
  const auto n = static_cast<double>(r.plan.runs.size());
  sum.set("runs", n);
  sum.set("runs_executed", static_cast<double>(r.stats.executed));
  sum.set("runs_cached", static_cast<double>(r.stats.cached));
  sum.set("runs_failed", static_cast<double>(r.stats.failed));
  // Observed orders per refinement line; the label made a plain key
  // ("h element=tet10" -> fitted_order.h_element_tet10).
  for (const auto& l : r.outcome.lines) {
    if (!l.fitted_order) continue;
    std::string key;
    for (char c : l.label) key += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' ? c : '_';
    while (key.find("__") != std::string::npos) key.erase(key.find("__"), 1);
    while (!key.empty() && key.back() == '_') key.pop_back();
    sum.set("fitted_order." + key, *l.fitted_order);
    if (l.richardson && l.richardson->ok) sum.set("richardson_order." + key, l.richardson->observed_order);
  }
  double min_error = std::numeric_limits<double>::quiet_NaN();
  for (double e : r.outcome.error)
    if (std::isfinite(e) && !(e >= min_error)) min_error = e;
  if (std::isfinite(min_error)) sum.set("error_min", min_error);
  if (study.tolerance) sum.set("tolerance", *study.tolerance);
  if (r.outcome.cheapest) {
    const std::size_t c = *r.outcome.cheapest;
    sum.set_text("cheapest_run", r.plan.runs[c].label);
    sum.set("cheapest_error", r.outcome.error[c]);
    sum.set("cheapest_wall_time", r.results[c].wall_s, "s");
  } else if (study.tolerance) {
    sum.set_text("cheapest_run", "none within tolerance");
  }
  sum.note("study", study.name);
  sum.note("qoi", study.qoi);
  sum.note("error_kind", r.outcome.relative_error ? "relative" : "absolute");
  sum.note("reference", r.outcome.reference_note);
  // wall_time_s / peak_memory_mb: this process (the study driver); each
  // run's own are in study.csv.
  return sum;
}

int run_error_study(const fs::path& file, const ErrorStudyOptions& o, std::ostream& out, ErrorStudyResult* result) {
  const StudyConfig study = load_study(file);
  ErrorStudyResult local;
  ErrorStudyResult& r = result ? *result : local;
  r.out_dir = o.out_dir.empty() ? file.parent_path() / (study.name + ".study") : o.out_dir;
  r.plan = plan_study(study);
  const std::size_t n = r.plan.runs.size();
  // A reference the runs' inputs cannot give (a key missing for the
  // reference, a load case it does not cover) is an InputError before
  // anything runs, dry run included; the shooting reference caches its solve.
  for (const auto& run : r.plan.runs) analytic_reference(study, run.input);
  const HostInfo host = this_host(o.binary);

  std::vector<std::optional<double>> measured(n);
  std::size_t cached = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const fs::path dir = run_dir(r.out_dir, r.plan.runs[i]);
    if (auto c = cached_result(dir, host, o.reuse_timings)) {
      measured[i] = c->wall_s;
      ++cached;
    } else if (auto any = cached_result(dir, host, true)) {
      measured[i] = any->wall_s;  // another host or binary: a fair estimate, still re-run
    }
  }
  // Nothing measured yet: the study file's recorded base time stands in for the base run.
  const bool nothing_measured = std::none_of(measured.begin(), measured.end(), [](const auto& m) { return m.has_value(); });
  std::vector<std::optional<double>> estimates_from = measured;
  if (nothing_measured && study.base_time_s) estimates_from[0] = *study.base_time_s;  // runs[0] is the base
  if (o.dry_run) {
    out << fmt::format("study {}: {} runs ({} cached, {} to run) in {}\n", study.name, n, cached, n - cached, r.out_dir.string());
    double total = 0;
    bool unknown = false;
    for (std::size_t i = 0; i < n; ++i) {
      const bool is_cached = cached_result(run_dir(r.out_dir, r.plan.runs[i]), host, o.reuse_timings).has_value();
      const double est = estimate_seconds(study, r.plan, i, estimates_from);
      if (!is_cached) {
        if (est >= 0) total += est;
        else unknown = true;
      }
      out << fmt::format("  {} {:<50} ranks {}  {}\n", r.plan.runs[i].key.substr(0, 8), r.plan.runs[i].label, r.plan.runs[i].ranks,
                         is_cached ? "cached" : est >= 0 ? fmt::format("~{:.1f} s", est) : "unknown (nothing measured yet)");
    }
    out << fmt::format("estimated time to run: {:.0f} s{}{}\n", total, unknown ? " + runs without an estimate" : "",
                       nothing_measured && study.base_time_s ? fmt::format(" (from the study's base_time {:.3g} s)", *study.base_time_s)
                       : nothing_measured ? " (nothing measured yet: give base_time in the study file for an estimate)"
                                          : "");
    if (n - cached > kMaxRunsWithoutYes) out << fmt::format("more than {} runs to do: the real run needs --yes\n", kMaxRunsWithoutYes);
    return 0;
  }
  if (n - cached > kMaxRunsWithoutYes && !o.yes)
    throw InputError(fmt::format("{}: the study has {} runs to do (more than {}); check it with --dry-run and confirm with --yes",
                                 file.string(), n - cached, kMaxRunsWithoutYes));
  out << fmt::format("study {}: {} runs ({} cached) in {}\n", study.name, n, cached, r.out_dir.string()) << std::flush;
  ExecOptions eo;
  eo.binary = o.binary;
  eo.jobs = o.jobs;
  eo.cores = o.cores;
  eo.reuse_timings = o.reuse_timings;
  eo.out = &out;
  r.stats = execute_runs(study, r.plan, r.out_dir, eo, r.results);
  // A successful run without the study's QoI is a failed row (exit 1), never
  // a silently missing point.
  const int missing = fail_runs_missing_qoi(study, r.plan, r.results);
  r.stats.failed += missing;
  if (missing > 0) {
    const auto first = std::find_if(r.results.begin(), r.results.end(), [&](const RunResult& x) {
      return x.status == "failed" && x.message.find("is not in the summary.yaml") != std::string::npos;
    });
    out << fmt::format("error: {} of {} runs succeeded but did not write qoi '{}'; first: {}\n", missing, n, study.qoi, first->message);
  }
  r.outcome = evaluate_study(study, r.plan, r.results);
  r.files = write_report(study, r.plan, r.results, r.outcome, r.out_dir);
  out << fmt::format("{} runs executed, {} cached, {} failed; reference: {}\n", r.stats.executed, r.stats.cached, r.stats.failed,
                     r.outcome.reference_note);
  if (!r.outcome.error_note.empty()) out << "note: " << r.outcome.error_note << "\n";
  for (const auto& l : r.outcome.lines)
    if (l.fitted_order) out << fmt::format("  order along {}: fitted {:.3f}\n", l.label, *l.fitted_order);
  if (r.outcome.cheapest)
    out << fmt::format("cheapest within tolerance {:.3g}: {} ({:.3g} s)\n", *study.tolerance, r.plan.runs[*r.outcome.cheapest].label,
                       r.results[*r.outcome.cheapest].wall_s);
  error_study_summary(study, r).write(r.out_dir / "summary.yaml");
  out << fmt::format("wrote {}, {} and summary.yaml\n", r.files.csv.string(), r.files.markdown.string());
  return r.stats.failed > 0 ? 1 : 0;
}

}  // namespace stentsim::study
