#include "workflows/study/study_report.hpp"

#include "common/config.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include "common/error.hpp"
#include "common/files.hpp"
#include "workflows/plots/figure.hpp"
#include "workflows/study/analytic_references.hpp"

namespace fs = std::filesystem;

namespace stentsim::study {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double norm(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s);
}

const Knob* find_knob(const StudyConfig& s, const std::string& name) {
  for (const auto& k : s.knobs)
    if (k.name == name) return &k;
  return nullptr;
}

std::string num(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : ""; }

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

std::string md(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c == '\n' ? ' ' : c);
  return out;
}

std::string join(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : " ") + num(x);
  return s;
}

}  // namespace

int fail_runs_missing_qoi(const StudyConfig& s, const StudyPlan& plan, std::vector<RunResult>& results) {
  int marked = 0;
  for (std::size_t i = 0; i < results.size() && i < plan.runs.size(); ++i) {
    RunResult& r = results[i];
    if (r.status != "ok" || r.qoi.count(s.qoi)) continue;
    std::vector<std::string> names;
    for (const auto& [name, v] : r.qoi)
      if (name != kPerRankMemoryQoi) names.push_back(name);
    std::stable_sort(names.begin(), names.end(),
                     [&](const std::string& a, const std::string& b) { return edit_distance(a, s.qoi) < edit_distance(b, s.qoi); });
    const std::string closest = closest_name(names, s.qoi);
    const std::string hint = closest.empty() ? std::string() : fmt::format(" (did you mean '{}'?)", closest);
    std::string present;
    for (const auto& n : names) present += (present.empty() ? "" : ", ") + n;
    r.status = "failed";
    r.message = fmt::format("{}: qoi '{}' is not in the summary.yaml of run {} ({}){}; its numeric QoIs are: {}", s.file.string(),
                            s.qoi, plan.runs[i].key.substr(0, 8), plan.runs[i].label, hint, present.empty() ? "none" : present);
    ++marked;
  }
  return marked;
}

StudyOutcome evaluate_study(const StudyConfig& s, const StudyPlan& plan, const std::vector<RunResult>& results) {
  StudyOutcome o;
  const std::size_t n = plan.runs.size();
  o.value.assign(n, kNaN);
  o.reference.assign(n, {});
  o.error.assign(n, kNaN);
  std::vector<std::vector<double>> q(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (results[i].status != "ok") continue;
    auto it = results[i].qoi.find(s.qoi);
    if (it == results[i].qoi.end()) continue;
    q[i] = it->second;
    o.value[i] = q[i].size() == 1 ? q[i][0] : norm(q[i]);
  }
  o.relative_error = s.relative_error;
  auto error_of = [&](const std::vector<double>& v, const std::vector<double>& ref) {
    if (v.size() != ref.size())
      throw InputError(fmt::format("{}: qoi '{}' has {} components but the reference has {}", s.file.string(), s.qoi, v.size(), ref.size()));
    std::vector<double> d(v.size());
    for (std::size_t k = 0; k < v.size(); ++k) d[k] = v[k] - ref[k];
    return o.relative_error ? norm(d) / norm(ref) : norm(d) / s.error_scale;
  };
  // Relative errors divide by the reference: when the QoI tends to 0 (a
  // reference at or below kVanishingQoi of the largest QoI value of the
  // study, e.g. the roll-up tip back at the root, where the closed form is 0
  // up to round-off) they would measure that round-off. The study then
  // reports absolute errors (/ error_scale) and says so everywhere.
  auto check_relative = [&] {
    if (!o.relative_error) return;
    double largest = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (!q[i].empty()) largest = std::max(largest, norm(q[i]));
    for (std::size_t i = 0; i < n; ++i) {
      if (o.reference[i].empty() || q[i].empty()) continue;
      const double r = norm(o.reference[i]);
      if (r > kVanishingQoi * largest && r > 0) continue;
      o.relative_error = false;
      o.error_note = fmt::format(
          "relative error refused: the QoI tends to 0 (reference |{}| = {:.3g} for run {} ({}) is at most {:g} of the largest "
          "value {:.3g}); errors are ABSOLUTE, |value - reference| / error_scale ({:g}). Write 'error: absolute' in {} to "
          "make this explicit",
          s.qoi, r, plan.runs[i].key.substr(0, 8), plan.runs[i].label, kVanishingQoi, largest, s.error_scale, s.file.filename().string());
      return;
    }
  };

  using T = Reference::Type;
  switch (s.reference.type) {
    case T::tube_plane_strain:
    case T::beam_rollup:
    case T::beam_plastic_rollup:
    case T::beam_shooting:
    case T::value:
      o.reference_note = s.reference.type == T::tube_plane_strain     ? "plane-strain neo-Hooke tube, shooting solution (Odeint) per run"
                         : s.reference.type == T::beam_rollup         ? "closed-form end-moment roll-up per run"
                         : s.reference.type == T::beam_plastic_rollup ? "closed-form elasto-plastic moment-curvature (App. C) end-moment "
                                                                        "cantilever per run"
                         : s.reference.type == T::beam_shooting ? "Simo-Reissner rod under the dead tip force, RK4 shooting per run"
                                                                : "given value";
      for (std::size_t i = 0; i < n; ++i) o.reference[i] = analytic_reference(s, plan.runs[i].input);
      check_relative();
      for (std::size_t i = 0; i < n; ++i)
        if (!q[i].empty()) o.error[i] = error_of(q[i], o.reference[i]);
      break;
    case T::qoi_is_error:
      o.reference_note = fmt::format("the QoI '{}' is itself the error against the known truth", s.qoi);
      for (std::size_t i = 0; i < n; ++i)
        if (!q[i].empty()) o.error[i] = norm(q[i]) / (s.relative_error ? 1.0 : s.error_scale);
      break;
    case T::richardson: {
      const Knob& k = *find_knob(s, s.reference.knob);
      std::vector<double> h, f;
      std::vector<std::size_t> idx;
      for (const auto& line : plan.lines)
        if (line.label == k.name)
          for (std::size_t j = 0; j < line.runs.size(); ++j)
            if (q[line.runs[j]].size() == 1) {
              h.push_back(k.h[static_cast<std::size_t>(line.settings[j])]);
              f.push_back(q[line.runs[j]][0]);
              idx.push_back(line.runs[j]);
            }
      if (h.size() < 3) {
        o.reference_note = fmt::format("Richardson along '{}': fewer than three scalar solutions, no reference", k.name);
        break;
      }
      // The reference line is the one-at-a-time line: the other knobs at the base.
      const Richardson r = richardson(h, f, theoretical_order_for(s, k, {}));
      double ref = r.extrapolated;
      if (r.ok) {
        o.reference_note = fmt::format("Richardson extrapolation along '{}' (ratio {:.3g}, observed order {:.3g}, {})", k.name, r.ratio,
                                       r.observed_order,
                                       r.tends_to_zero ? fmt::format("QoI tends to 0: relative GCI undefined, absolute GCI fine {:.3g}",
                                                                     r.gci_fine_absolute)
                                                       : fmt::format("GCI fine {:.3g}", r.gci_fine));
      } else {
        // Not extrapolated: errors are differences to the finest run, and say so.
        const auto finest = std::min_element(h.begin(), h.end()) - h.begin();
        ref = f[static_cast<std::size_t>(finest)];
        o.reference_note = fmt::format("Richardson along '{}' NOT done ({}); errors below are differences to the finest run", k.name,
                                       r.message);
      }
      for (std::size_t i = 0; i < n; ++i)
        if (q[i].size() == 1) o.reference[i] = {ref};
      check_relative();
      for (std::size_t i = 0; i < n; ++i)
        if (q[i].size() == 1) o.error[i] = error_of(q[i], o.reference[i]);
      break;
    }
  }

  for (const auto& line : plan.lines) {
    LineSummary ls{line.label, line.knob, {}, {}, {}, {}, std::nullopt, std::nullopt, {}, std::nullopt};
    const Knob& k = *find_knob(s, line.knob);
    if (!line.runs.empty()) ls.theoretical_order = theoretical_order_for(s, k, plan.runs[line.runs.front()].setting);
    for (std::size_t j = 0; j < line.runs.size(); ++j) {
      ls.runs.push_back(line.runs[j]);
      ls.h.push_back(k.h.empty() ? kNaN : k.h[static_cast<std::size_t>(line.settings[j])]);
      ls.error.push_back(o.error[line.runs[j]]);
      ls.value.push_back(o.value[line.runs[j]]);
    }
    if (!k.h.empty()) {
      ls.fitted_order = fitted_order(ls.h, ls.error);
      ls.pairwise_orders = pairwise_orders(ls.h, ls.error);
      if (ls.h.size() >= 3) ls.richardson = richardson(ls.h, ls.value, ls.theoretical_order);
    }
    o.lines.push_back(std::move(ls));
  }

  std::vector<std::size_t> ok;
  for (std::size_t i = 0; i < n; ++i)
    if (results[i].status == "ok" && std::isfinite(o.error[i])) ok.push_back(i);
  std::sort(ok.begin(), ok.end(), [&](auto a, auto b) { return results[a].wall_s < results[b].wall_s; });
  double best = std::numeric_limits<double>::infinity();
  for (auto i : ok)
    if (o.error[i] < best) {
      o.pareto.push_back(i);
      best = o.error[i];
    }
  if (s.tolerance)
    for (auto i : ok)
      if (o.error[i] <= *s.tolerance) {
        o.cheapest = i;
        break;
      }
  return o;
}

plots::Figure error_vs_h_figure(const StudyConfig& s, const StudyOutcome& o) {
  plots::Figure f;
  f.title = fmt::format("{}: error of {} against mesh size", s.name, s.qoi);
  f.x = {"h", "mm", true, std::nullopt, std::nullopt, {}};
  f.y = {o.relative_error ? "relative error" : "error", "", true, std::nullopt, std::nullopt, {}};
  int slot = 0;  // one colour (and marker) per line, shared by its fit
  for (const auto& line : o.lines) {
    if (line.h.empty() || !std::isfinite(line.h.front())) continue;
    plots::Series ser{line.label, {}, {}, plots::Style::markers, plots::Marker::automatic};
    ser.colour = slot;
    for (std::size_t j = 0; j < line.h.size(); ++j) {
      if (!(std::isfinite(line.error[j]) && line.error[j] > 0)) continue;
      ser.x.push_back(line.h[j]);
      ser.y.push_back(line.error[j]);
    }
    if (ser.x.empty()) continue;
    ++slot;
    if (line.fitted_order && ser.x.size() >= 2) {
      // The fitted power law e = C h^p through the points' geometric mean,
      // dashed in the line's colour, in the legend with its order.
      double lx = 0, ly = 0;
      for (std::size_t j = 0; j < ser.x.size(); ++j) {
        lx += std::log(ser.x[j]);
        ly += std::log(ser.y[j]);
      }
      lx /= static_cast<double>(ser.x.size());
      ly /= static_cast<double>(ser.x.size());
      const auto [mn, mx] = std::minmax_element(ser.x.begin(), ser.x.end());
      plots::Series fit{fmt::format("{} fit p = {:.2f}", line.label, *line.fitted_order), {*mn, *mx}, {},
                        plots::Style::lines, plots::Marker::automatic};
      fit.colour = ser.colour;
      fit.dashed = true;
      for (double x : fit.x) fit.y.push_back(std::exp(ly + *line.fitted_order * (std::log(x) - lx)));
      f.series.push_back(std::move(ser));
      f.series.push_back(std::move(fit));
    } else {
      f.series.push_back(std::move(ser));
    }
  }
  return f;
}

ReportFiles write_report(const StudyConfig& s, const StudyPlan& plan, const std::vector<RunResult>& results, const StudyOutcome& o,
                         const fs::path& out_dir) {
  ReportFiles files;
  fs::create_directories(out_dir);
  const std::set<std::size_t> front(o.pareto.begin(), o.pareto.end());
  std::set<std::string> qoi_names;
  for (const auto& r : results)
    for (const auto& [name, v] : r.qoi) qoi_names.insert(name);

  // study.csv
  {
    std::ostringstream csv;
    csv << "run,label,status,cached";
    for (const auto& k : s.knobs) csv << "," << csv_field(k.name);
    csv << ",qoi,value,reference,error,error_kind,wall_time_s,cpu_time_s,peak_memory_mb,peak_memory_rule,ranks,host,nproc,load_average,binary_version,pareto,message";
    for (const auto& name : qoi_names) csv << "," << csv_field("qoi." + name);
    csv << "\n";
    for (std::size_t i = 0; i < plan.runs.size(); ++i) {
      const auto& r = results[i];
      const auto& run = plan.runs[i];
      csv << run.key << "," << csv_field(run.label) << "," << r.status << "," << (r.cached ? "yes" : "no");
      for (const auto& k : s.knobs) csv << "," << csv_field(setting_label(s, run, k.name));
      csv << "," << s.qoi << "," << num(o.value[i]) << "," << join(o.reference[i]) << "," << num(o.error[i]) << "," << (o.relative_error ? "relative" : "absolute") << "," << num(r.wall_s)
          << "," << num(r.cpu_s) << "," << num(r.peak_memory_mb) << "," << csv_field(r.peak_memory_rule) << "," << run.ranks << "," << csv_field(r.host) << "," << r.nproc << ","
          << num(r.load_average) << "," << r.version << "," << (front.count(i) ? "yes" : "no") << "," << csv_field(r.message);
      for (const auto& name : qoi_names) {
        auto it = r.qoi.find(name);
        csv << "," << (it == r.qoi.end() ? "" : join(it->second));
      }
      csv << "\n";
    }
    files.csv = out_dir / "study.csv";
    files::write_atomic(files.csv, csv.str());
  }

  // Plots: error against wall time (one line per knob line, the front marked)
  // and error against h with the fitted order.
  auto positive = [](double v) { return std::isfinite(v) && v > 0 ? v : kNaN; };
  std::vector<std::string> plot_notes;
  {
    plots::Figure f;
    f.title = fmt::format("{}: error of {} against wall time", s.name, s.qoi);
    f.x = {"wall time", "s", true, std::nullopt, std::nullopt, {}};
    f.y = {o.relative_error ? "relative error" : "error", "", true, std::nullopt, std::nullopt, {}};
    bool any = false;
    for (const auto& line : o.lines) {
      plots::Series ser{line.label, {}, {}, plots::Style::lines_and_markers, plots::Marker::automatic};
      for (std::size_t j = 0; j < line.runs.size(); ++j) {
        const double w = results[line.runs[j]].wall_s, e = positive(line.error[j]);
        if (!(w > 0) || !std::isfinite(e)) continue;
        ser.x.push_back(w);
        ser.y.push_back(e);
      }
      if (ser.x.empty()) continue;
      // Sorted by time so the line reads left to right.
      std::vector<std::size_t> ord(ser.x.size());
      for (std::size_t j = 0; j < ord.size(); ++j) ord[j] = j;
      std::sort(ord.begin(), ord.end(), [&](auto a, auto b) { return ser.x[a] < ser.x[b]; });
      plots::Series sorted{ser.label, {}, {}, ser.style, ser.marker};
      for (auto j : ord) {
        sorted.x.push_back(ser.x[j]);
        sorted.y.push_back(ser.y[j]);
      }
      f.series.push_back(std::move(sorted));
      any = true;
    }
    // Under the lines: a line whose points are all on the front stays visible.
    plots::Highlight front_h{"Pareto front", {}, {}, plots::Marker::diamond, true, false, true};
    for (auto i : o.pareto)
      if (results[i].wall_s > 0 && o.error[i] > 0) {
        front_h.x.push_back(results[i].wall_s);
        front_h.y.push_back(o.error[i]);
      }
    if (!front_h.x.empty()) f.highlights.push_back(front_h);
    if (any) {
      for (const char* ext : {".png", ".svg"}) {
        const fs::path p = out_dir / (std::string("error_vs_wall_time") + ext);
        plots::write_figure(f, p);
        files.plots.push_back(p);
      }
    } else {
      plot_notes.push_back("error_vs_wall_time: no run with a positive error, not drawn");
    }
  }
  {
    const plots::Figure f = error_vs_h_figure(s, o);
    const bool any = !f.series.empty();
    if (any) {
      for (const char* ext : {".png", ".svg"}) {
        const fs::path p = out_dir / (std::string("error_vs_h") + ext);
        plots::write_figure(f, p);
        files.plots.push_back(p);
      }
    } else {
      plot_notes.push_back("error_vs_h: no knob with mesh sizes (h) and positive errors, not drawn");
    }
  }

  // study.md
  {
    std::ostringstream m;
    m << "# Error study: " << md(s.name) << "\n\n";
    m << "Study file: `" << s.file.string() << "`; base: `" << s.base_file.string() << "`; QoI: `" << s.qoi << "`; error: "
      << (o.relative_error ? "relative" : fmt::format("absolute / {}", s.error_scale)) << ".\n\n";
    if (!o.error_note.empty()) m << "**Note:** " << md(o.error_note) << ".\n\n";
    m << "Reference: " << md(o.reference_note) << ".\n\n";
    std::set<std::string> hosts;
    for (const auto& r : results)
      if (!r.host.empty()) hosts.insert(fmt::format("{} ({} cores, {})", r.host, r.nproc, r.version));
    for (const auto& h : hosts) m << "Host: " << md(h) << "\n";
    m << "\n| run | setting | status | value | error | wall s | CPU s | peak MB | ranks | load | Pareto |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (std::size_t i = 0; i < plan.runs.size(); ++i) {
      const auto& r = results[i];
      m << fmt::format("| {} | {} | {}{} | {} | {} | {} | {} | {} | {} | {} | {} |\n", plan.runs[i].key.substr(0, 8), md(plan.runs[i].label),
                       r.status, r.cached ? " (cached)" : "", num(o.value[i]), num(o.error[i]), num(r.wall_s), num(r.cpu_s),
                       num(r.peak_memory_mb), plan.runs[i].ranks, num(r.load_average), front.count(i) ? "yes" : "");
    }
    bool any_failed = false;
    for (std::size_t i = 0; i < plan.runs.size(); ++i)
      if (results[i].status != "ok") {
        if (!any_failed) m << "\n## Failed runs\n\n";
        any_failed = true;
        m << "- " << plan.runs[i].key.substr(0, 8) << " " << md(plan.runs[i].label) << ": " << md(results[i].message) << "\n";
      }
    bool any_order = false;
    for (const auto& l : o.lines)
      if (!l.pairwise_orders.empty()) any_order = true;
    if (any_order) {
      m << "\n## Orders\n\n| line | h | error | pairwise orders | fitted order | theoretical | Richardson (QoI only) |\n|---|---|---|---|---|---|---|\n";
      for (const auto& l : o.lines) {
        if (l.pairwise_orders.empty()) continue;
        std::string rich = "-";
        if (l.richardson)
          rich = !l.richardson->ok ? l.richardson->message
                 : l.richardson->tends_to_zero
                     ? fmt::format("p = {:.3g}, extrapolated {:.8g}, QoI tends to 0: absolute GCI {:.3g} (relative undefined)",
                                   l.richardson->observed_order, l.richardson->extrapolated, l.richardson->gci_fine_absolute)
                     : fmt::format("p = {:.3g}, extrapolated {:.8g}, GCI {:.3g}", l.richardson->observed_order,
                                   l.richardson->extrapolated, l.richardson->gci_fine);
        m << fmt::format("| {} | {} | {} | {} | {} | {} | {} |\n", md(l.label), join(l.h), join(l.error), join(l.pairwise_orders),
                         l.fitted_order ? fmt::format("{:.3f}", *l.fitted_order) : "-",
                         l.theoretical_order ? fmt::format("{:.3g}", *l.theoretical_order) : "-", md(rich));
      }
    }
    m << "\n## Cheapest within tolerance\n\n";
    if (s.tolerance && !o.error_note.empty()) m << "The tolerance is compared with the absolute errors (see the note above).\n\n";
    if (!s.tolerance) m << "No `tolerance` in the study file.\n";
    else if (o.cheapest)
      m << fmt::format("Tolerance {:.3g}: **{}** (error {:.3g}, {:.3g} s wall).\n", *s.tolerance, md(plan.runs[*o.cheapest].label),
                       o.error[*o.cheapest], results[*o.cheapest].wall_s);
    else m << fmt::format("Tolerance {:.3g}: no run reaches it.\n", *s.tolerance);
    m << "\nPareto front (error against wall time): ";
    for (std::size_t j = 0; j < o.pareto.size(); ++j) m << (j ? "; " : "") << md(plan.runs[o.pareto[j]].label);
    m << "\n\nPlots:";
    for (const auto& p : files.plots) m << " `" << p.filename().string() << "`";
    for (const auto& n : plot_notes) m << "\n" << n;
    m << "\n\nPeak memory: wait4() of each run's process; for a run on several MPI ranks the sum of the ranks' own peaks "
         "(summary.yaml `" << kPerRankMemoryQoi << "`), see the CSV's peak_memory_rule.\n";
    files.markdown = out_dir / "study.md";
    files::write_atomic(files.markdown, m.str());
  }
  return files;
}

}  // namespace stentsim::study
