#include "workflows/report/report_figures.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>

#include "workflows/plots/figure.hpp"

namespace fs = std::filesystem;

namespace stentsim::workflows::report {
namespace {

using plots::Figure;
using plots::Series;

plots::Axis axis(std::string label, std::string unit) {
  plots::Axis a;
  a.label = std::move(label);
  a.unit = std::move(unit);
  return a;
}

Series series(std::string label, std::vector<double> x, std::vector<double> y) {
  Series s;
  s.label = std::move(label);
  s.x = std::move(x);
  s.y = std::move(y);
  return s;
}

bool any_finite(const std::vector<double>& v) {
  return std::any_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

std::vector<double> head(const std::vector<double>& v, std::size_t n) { return {v.begin(), v.begin() + std::min(n, v.size())}; }

// stent_ring_<k>_diameter columns in ring order (k as a number: ring 10 after ring 9).
std::vector<std::pair<int, std::string>> ring_columns(const History& h) {
  std::vector<std::pair<int, std::string>> rings;
  for (const auto& c : h.columns_like("stent_ring_", "_diameter")) {
    const std::string k = c.substr(11, c.size() - 11 - 9);
    char* end = nullptr;
    const long n = std::strtol(k.c_str(), &end, 10);
    if (!k.empty() && end == k.c_str() + k.size()) rings.emplace_back(static_cast<int>(n), c);
  }
  std::sort(rings.begin(), rings.end());
  return rings;
}

// The mean diameter and the rings' as series over `x` (the first `n` rows).
std::vector<Series> diameter_series(const History& h, const std::vector<double>& x, std::size_t n) {
  std::vector<Series> out;
  if (h.has("stent_diameter") && any_finite(head(h.column("stent_diameter"), n))) {
    Series s = series("mean", head(x, n), head(h.column("stent_diameter"), n));
    s.colour = 0;
    out.push_back(std::move(s));
  }
  int slot = 1;
  for (const auto& [k, c] : ring_columns(h)) {
    if (!any_finite(head(h.column(c), n))) continue;
    Series s = series(fmt::format("ring {}", k), head(x, n), head(h.column(c), n));
    s.colour = slot++ % 10;
    s.dashed = true;  // the rings are the detail; the mean is the line to follow
    out.push_back(std::move(s));
  }
  return out;
}

class Writer {
 public:
  Writer(fs::path dir, FigureSet& set) : dir_(std::move(dir)), set_(set) {}

  void emit(Figure f, const std::string& name, const std::string& caption) {
    // One series needs no legend: its name goes to the axis, and the plot keeps the width.
    if (f.series.size() == 1 && f.highlights.empty()) {
      if (f.legend && !f.series.front().label.empty()) f.y.label += " (" + f.series.front().label + ")";
      f.legend = false;
    }
    f.width_px = 1000;
    WrittenFigure w{name, f.title, caption, dir_ / (name + ".png"), dir_ / (name + ".svg")};
    plots::write_png(f, w.png);
    plots::write_svg(f, w.svg);
    set_.written.push_back(std::move(w));
  }
  void omit(const std::string& title, const std::string& why) { set_.omitted.push_back({title, why}); }

 private:
  fs::path dir_;
  FigureSet& set_;
};

Figure over_time(const std::string& title, const std::string& y_label, const std::string& y_unit) {
  Figure f;
  f.title = title;
  f.x = axis("pseudo-time", "s");
  f.y = axis(y_label, y_unit);
  return f;
}

std::vector<Series> columns_over(const History& h, const std::vector<std::string>& cols, const std::vector<double>& x,
                                 const std::function<std::string(const std::string&)>& label) {
  std::vector<Series> out;
  for (const auto& c : cols)
    if (any_finite(h.column(c))) out.push_back(series(label(c), x, h.column(c)));
  return out;
}

std::string strip(const std::string& c, const std::string& prefix, const std::string& suffix) {
  return c.substr(prefix.size(), c.size() - prefix.size() - suffix.size());
}

void diameter_vs_pressure(const FigureInputs& in, Writer& w) {
  const History& h = *in.history;
  const std::string title = "Stent diameter against inflation pressure";
  const auto p = inflation_pressure_column(h);
  if (!p) return w.omit(title, "history.csv has no inflation pressure column (a pressure_<condition> other than pressure_diastolic)");
  const std::size_t n = inflation_end(h.column(*p));
  if (n < 2) return w.omit(title, fmt::format("{} never rises above 0 in more than one row", *p));
  auto series = diameter_series(h, h.column(*p), n);
  if (series.empty()) return w.omit(title, "history.csv has no stent_diameter or stent_ring_<k>_diameter values");
  Figure f;
  f.title = title;
  f.x = axis("inflation pressure", "MPa");
  f.x.min = 0.0;
  f.y = axis("stent diameter", "mm");
  f.series = std::move(series);
  for (const auto& pt : in.diameter_vs_pressure) {
    plots::Highlight hl;
    hl.label = pt.label;
    hl.x = {pt.x};
    hl.y = {pt.y};
    hl.marker = plots::Marker::diamond;
    f.highlights.push_back(std::move(hl));
  }
  w.emit(f, "stent_diameter_vs_pressure",
         fmt::format("x: {} (MPa; 1 atm = 0.101325 MPa), the {} rows of the inflation up to its maximum; y: stent_diameter (mean over "
                     "rings) and stent_ring_<k>_diameter{}.",
                     *p, n, in.diameter_vs_pressure.empty() ? "" : "; diamond: the paper's diameter at its pressure"));
}

void diameter_over_time(const FigureInputs& in, Writer& w) {
  const History& h = *in.history;
  const std::string title = "Stent diameter over the run";
  auto series = diameter_series(h, h.column("time"), h.rows);
  if (series.empty()) return w.omit(title, "history.csv has no stent_diameter or stent_ring_<k>_diameter values");
  Figure f = over_time(title, "stent diameter", "mm");
  f.series = std::move(series);
  w.emit(f, "stent_diameter_over_time", "stent_diameter (mean over rings) and stent_ring_<k>_diameter against the pseudo-time.");
}

void dogboning_over_time(const FigureInputs& in, Writer& w) {
  const History& h = *in.history;
  const std::string title = "Dogboning over the run";
  if (!any_finite(h.column("stent_dogboning_percent"))) return w.omit(title, "history.csv has no stent_dogboning_percent values");
  Figure f = over_time(title, "dogboning (r_distal - r_central)/r_distal", "%");
  f.series.push_back(series("stent", h.column("time"), h.column("stent_dogboning_percent")));
  f.legend = false;  // the axis says what it is
  w.emit(f, "dogboning_over_time", "stent_dogboning_percent against the pseudo-time (DESIGN.md §8 definition).");
}

void pressures_over_time(const FigureInputs& in, Writer& w) {
  const History& h = *in.history;
  const std::string title = "Applied pressures over the run";
  auto series = columns_over(h, h.columns_like("pressure_", ""), h.column("time"),
                             [](const std::string& c) { return c.substr(9); });
  if (series.empty()) return w.omit(title, "history.csv has no pressure_<condition> values");
  Figure f = over_time(title, "pressure", "MPa");
  f.series = std::move(series);
  w.emit(f, "pressures_over_time", "The pressure_<condition> columns: the load the other time plots follow.");
}

void contact_over_time(const FigureInputs& in, Writer& w) {
  const History& h = *in.history;
  const std::string title = "Contact forces over the run";
  auto series = columns_over(h, h.columns_like("contact_", "_force"), h.column("time"),
                             [](const std::string& c) { return strip(c, "contact_", "_force"); });
  if (series.empty()) return w.omit(title, "history.csv has no contact_<pair>_force values");
  Figure f = over_time(title, "contact force", "N");
  f.series = std::move(series);
  w.emit(f, "contact_forces_over_time", "contact_<pair>_force (the normal contact force summed over the pair) against the pseudo-time.");
}

void stresses_over_time(const FigureInputs& in, Writer& w) {
  const History& h = *in.history;
  const std::string title = "Maximum principal stress per layer over the run";
  auto series = columns_over(h, h.columns_like("max_principal_", "_kpa"), h.column("time"), [](const std::string& c) {
    std::string layer = strip(c, "max_principal_", "_kpa");
    if (layer.size() > 6 && layer.compare(layer.size() - 6, 6, "_nodal") == 0) layer = layer.substr(0, layer.size() - 6) + " (nodal)";
    return layer;
  });
  if (series.empty()) return w.omit(title, "history.csv has no max_principal_<layer>_kpa values (no artery in this scene, or not measured)");
  Figure f = over_time(title, "max principal stress", "kPa");
  f.series = std::move(series);
  w.emit(f, "layer_stresses_over_time", "max_principal_<layer>_kpa (Gauss-point maximum per layer) against the pseudo-time.");
}

void newton_per_step(const FigureInputs& in, Writer& w) {
  const History& h = *in.history;
  const std::string title = "Newton iterations per step";
  if (!any_finite(h.column("newton_iterations"))) return w.omit(title, "history.csv has no rows");
  Figure f;
  f.title = title;
  f.x = axis("step", "");
  f.y = axis("Newton iterations", "");
  f.y.min = 0.0;
  Series s = series("", h.column("step"), h.column("newton_iterations"));
  s.style = plots::Style::lines_and_markers;
  f.series.push_back(std::move(s));
  plots::Highlight cuts;
  cuts.label = "step needed cuts";
  cuts.marker = plots::Marker::cross;
  cuts.warning_colour = true;
  const auto& c = h.column("step_cuts");
  for (std::size_t i = 0; i < h.rows; ++i)
    if (std::isfinite(c[i]) && c[i] > 0) {
      cuts.x.push_back(h.column("step")[i]);
      cuts.y.push_back(h.column("newton_iterations")[i]);
    }
  if (!cuts.x.empty()) f.highlights.push_back(std::move(cuts));
  w.emit(f, "newton_iterations", "newton_iterations per converged step; crosses: steps that needed step cuts (step_cuts > 0).");
}

void balloon_profile(const FigureInputs& in, Writer& w) {
  const std::string title = "Balloon profile";
  const auto& q = in.solve->qois();
  auto z = q.find("balloon_profile_z");
  const auto* zv = z == q.end() ? nullptr : std::get_if<std::vector<double>>(&z->second.value);
  if (!zv) return w.omit(title, "solve/summary.yaml has no balloon_profile_z list");
  Figure f;
  f.title = title;
  f.x = axis("axial position z", "mm");
  f.y = axis("balloon diameter", "mm");
  std::vector<std::string> skipped;
  const std::string prefix = "balloon_profile_diameter_";
  for (const auto& [name, qoi] : q) {
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const auto* d = std::get_if<std::vector<double>>(&qoi.value);
    if (!d || d->size() != zv->size()) {
      skipped.push_back(fmt::format("{} ({} values, balloon_profile_z has {})", name, d ? d->size() : 1, zv->size()));
      continue;
    }
    f.series.push_back(series(name.substr(prefix.size()), *zv, *d));
  }
  if (f.series.empty())
    return w.omit(title, skipped.empty() ? "solve/summary.yaml has no balloon_profile_diameter_<label> list"
                                         : fmt::format("no profile matches balloon_profile_z: {}", fmt::join(skipped, ", ")));
  std::string caption = "balloon_profile_diameter_<label> against balloon_profile_z, one line per pressure.";
  if (!skipped.empty()) caption += fmt::format(" Not drawn (length differs from balloon_profile_z): {}.", fmt::join(skipped, ", "));
  w.emit(f, "balloon_profile", caption);
}

}  // namespace

FigureSet write_figures(const FigureInputs& in, const fs::path& figure_dir) {
  fs::create_directories(figure_dir);
  // A figure omitted now must not leave last run's file behind for the reader to find.
  for (const char* name : {"stent_diameter_vs_pressure", "stent_diameter_over_time", "dogboning_over_time", "contact_forces_over_time",
                           "layer_stresses_over_time", "pressures_over_time", "newton_iterations", "balloon_profile"})
    for (const char* ext : {".png", ".svg"}) fs::remove(figure_dir / (std::string(name) + ext));
  FigureSet set;
  Writer w(figure_dir, set);
  diameter_vs_pressure(in, w);
  diameter_over_time(in, w);
  dogboning_over_time(in, w);
  contact_over_time(in, w);
  stresses_over_time(in, w);
  pressures_over_time(in, w);
  newton_per_step(in, w);
  balloon_profile(in, w);
  return set;
}

}  // namespace stentsim::workflows::report
