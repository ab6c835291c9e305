#include "workflows/report/report_sections.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "common/units.hpp"

namespace fs = std::filesystem;

namespace stentsim::workflows::report {
namespace {

// Integers (counts, steps) without exponent; everything else to 4 digits.
std::string num(double v) {
  if (!std::isfinite(v)) return fmt::format("{}", v);
  if (v == std::round(v) && std::abs(v) < 1e12) return fmt::format("{:.0f}", v);
  return fmt::format("{:.4g}", v);
}

std::string memory_text(double mb) { return mb > 0 ? fmt::format("{:.0f} MB", mb) : "not recorded"; }

std::string qoi_value(const Qoi& q) {
  if (auto d = std::get_if<double>(&q.value)) return num(*d);
  if (auto v = std::get_if<std::vector<double>>(&q.value)) {
    if (v->empty()) return "empty list";
    const auto [lo, hi] = std::minmax_element(v->begin(), v->end());
    return fmt::format("{} values, {} to {}", v->size(), num(*lo), num(*hi));
  }
  return std::get<std::string>(q.value);
}

struct Known {
  std::string key, meaning;
};

// The solve QoIs the report knows, in reading order, with what they mean.
std::vector<Known> known_results() {
  std::vector<Known> k = {
      {"stent_diameter_initial", "stent diameter before inflation (mean over rings)"},
      {"stent_diameter_max", "stent diameter at the end of the inflation (max pressure)"},
      {"stent_diameter_after", "stent diameter after deflation"},
      {"recoil_percent", "elastic recoil"},
      {"dogboning_percent", "dogboning (r_distal - r_central)/r_distal, maximum over the inflation"},
      {"dogboning_pressure", "inflation pressure of that maximum"},
      {"dogboning_percent_at_0_8_pmax", "dogboning at 0.8 p_max"},
      {"dogboning_central_percent", "dogboning, (r_distal - r_central)/r_central variant"},
      {"balloon_dogboning_percent", "the balloon's dogboning (the paper's figure plots the balloon)"},
      {"stent_centroid_curvature_initial", "curvature of the stent's centroid line, initial"},
      {"stent_centroid_curvature_max", "curvature of the stent's centroid line at max pressure"},
      {"stent_centroid_curvature_after", "curvature of the stent's centroid line after deflation"},
      {"stent_bending_moment_max_max", "largest bending moment in the stent at max pressure"},
      {"stent_bending_moment_max_after", "largest bending moment in the stent after deflation"},
      {"contact_line_load_max_stent_balloon_max", "largest stent–balloon contact line load at max pressure"},
      {"contact_line_load_max_stent_balloon_after", "largest stent–balloon contact line load after deflation"},
      {"contact_line_load_max_stent_artery_max", "largest stent–artery contact line load at max pressure"},
      {"contact_line_load_max_stent_artery_after", "largest stent–artery contact line load after deflation"},
      {"malapposition_max_gap_after", "largest strut-to-endothelium gap after deflation"},
      {"malapposition_mean_gap_after", "mean strut-to-endothelium gap after deflation (gaps below 0, struts pressed in, count as 0)"},
      {"malapposed_fraction_after", "fraction of the stent's length malapposed after deflation (gap above the strut thickness)"},
      {"not_in_contact_fraction_after", "fraction of the stent's length not touching the endothelium after deflation"},
      {"malapposition_max_gap_max", "largest strut-to-endothelium gap at max pressure"},
      {"not_in_contact_fraction_max", "fraction of the stent's length not touching the endothelium at max pressure"},
      {"lumen_area_min_prestress", "minimal lumen area over the stented segment after the prestress (diastolic)"},
      {"lumen_area_min_after", "minimal lumen area over the stented segment after deflation"},
      {"lumen_area_min_max", "minimal lumen area over the stented segment at max pressure"},
      {"dogboning_time", "pseudo-time of the dogboning maximum"},
      {"artery_lumen_face_size", "mean edge of the artery's endothelium faces (peak stresses under struts depend on it)"},
      {"artery_max_displacement_prestress", "largest artery displacement under the diastolic prestress"},
  };
  const std::vector<std::pair<std::string, std::string>> times = {
      {"prestress", "after the prestress"}, {"max", "at max pressure"}, {"after", "after deflation"}};
  for (const char* layer : {"endothelium", "intima", "media", "adventitia"})
    for (const auto& [t, when] : times) {
      k.push_back({fmt::format("max_principal_{}_{}_kpa", layer, t), fmt::format("max principal stress, {}, {} (Gauss-point maximum)", layer, when)});
      k.push_back({fmt::format("max_principal_{}_{}_nodal_kpa", layer, t), fmt::format("max principal stress, {}, {} (nodal-averaged)", layer, when)});
    }
  k.push_back({"balloon_profile_z", "axial stations of the balloon profile"});
  k.push_back({"newton_iterations", "Newton iterations over the solve"});
  k.push_back({"steps", "converged load steps"});
  k.push_back({"wall_time_s", "solve wall time"});
  return k;
}

constexpr const char* kProfilePrefix = "balloon_profile_diameter_";

bool counts_mesh(const std::string& name) {
  return name.find("elements") != std::string::npos || name.find("nodes") != std::string::npos ||
         name.find("dofs") != std::string::npos;
}

}  // namespace

std::string shown_path(const ReportContext& c, const fs::path& path) {
  const fs::path rel = path.lexically_normal().lexically_relative(c.in->work_dir.lexically_normal());
  if (!rel.empty() && *rel.begin() != "..") return rel.generic_string();
  return path.string();
}

std::string duration_text(double s) {
  if (!(s > 0)) return "not recorded";
  if (s < 60) return fmt::format("{:.3g} s", s);
  if (s < 3600) return fmt::format("{:.3g} min", s / 60);
  return fmt::format("{:.3g} h", s / 3600);
}

void add_case_section(Document& doc, const ReportContext& c, const std::string& written_at) {
  const ReportInput& in = *c.in;
  doc.heading(2, "1. The case");
  std::vector<std::string> items = {
      fmt::format("name: {}", in.case_name),
      fmt::format("scene: {}", in.scene),
      fmt::format("case file: `{}`", in.case_file.string()),
      fmt::format("work folder: `{}`", in.work_dir.string()),
      in.pressure_max > 0 ? fmt::format("inflation pressure: {:.4g} MPa ({:.3g} atm)", in.pressure_max, in.pressure_max / units::kAtmInMPa)
                          : std::string("inflation pressure: not given"),
      fmt::format("paper numbers: {}", in.targets_key.empty() ? std::string("none for this case") : "`" + in.targets_key + "`"),
      fmt::format("report written: {}", written_at),
  };
  if (const auto* r = c.manifest.find("solve"); r && !r->finished.empty()) items.push_back(fmt::format("solve finished: {}", r->finished));
  if (!c.manifest.tool_version.empty()) items.push_back(fmt::format("stentsim version: {}", c.manifest.tool_version));
  doc.bullets(std::move(items));
}

void add_run_section(Document& doc, const ReportContext& c) {
  doc.heading(2, "2. The run");
  std::vector<std::vector<std::string>> rows;
  double total = 0, peak = 0;
  for (const auto& s : c.stages) {
    const auto* r = c.manifest.find(s);
    total += r->duration_s;
    peak = std::max(peak, r->peak_memory_mb);
    rows.push_back({s, r->status, duration_text(r->duration_s), memory_text(r->peak_memory_mb), r->finished, r->message});
  }
  rows.push_back({"all stages", "", duration_text(total) + " (sum)", memory_text(peak) + " (largest)", "", ""});
  doc.paragraph("Per stage, from `manifest.yaml` (this report stage is still running and is not listed):");
  doc.table({"stage", "status", "wall time", "peak memory", "finished", "message"}, std::move(rows));

  std::vector<std::vector<std::string>> counts;
  for (const auto& ss : c.stage_summaries)
    for (const auto& [name, q] : ss.summary.qois())
      if (counts_mesh(name))
        if (auto d = std::get_if<double>(&q.value)) counts.push_back({ss.stage, name, num(*d)});
  doc.heading(3, "Mesh sizes");
  if (counts.empty()) doc.paragraph("No earlier stage's `summary.yaml` reports element, node or DOF counts.");
  else doc.table({"stage", "quantity", "count"}, std::move(counts));

  doc.heading(3, "Solve");
  const History& h = c.history;
  const double newton = h.sum("newton_iterations"), wall = h.sum("wall_time_s");
  const double assembly = h.sum("assembly_s"), linear = h.sum("linear_solve_s");
  const double other = std::max(0.0, wall - assembly - linear);
  auto share = [&](double x) { return wall > 0 ? fmt::format(" ({:.0f} %)", 100 * x / wall) : std::string(); };
  auto summary_says = [&](const std::string& key, double ours) {
    auto it = c.solve.qois().find(key);
    if (it == c.solve.qois().end()) return std::string();
    auto d = std::get_if<double>(&it->second.value);
    return d && std::abs(*d - ours) > 1e-9 * std::max(1.0, std::abs(ours)) ? fmt::format(" (summary.yaml `{}`: {})", key, num(*d))
                                                                           : std::string();
  };
  std::vector<std::string> items = {
      fmt::format("converged steps: {}{}", h.rows, summary_says("steps", static_cast<double>(h.rows))),
      fmt::format("Newton iterations: {} in all{}{}", num(newton),
                  h.rows ? fmt::format(", {:.3g} per step", newton / static_cast<double>(h.rows)) : std::string(),
                  summary_says("newton_iterations", newton)),
      fmt::format("linear iterations: {} in all; step cuts: {}", num(h.sum("linear_iterations")), num(h.sum("step_cuts"))),
      fmt::format("solve wall time over the steps (sum of `history.csv` `wall_time_s`): {}: assembly {}{}, linear solve {}{}, "
                  "the rest (contact search, output, ...) {}{}",
                  duration_text(wall), duration_text(assembly), share(assembly), duration_text(linear), share(linear),
                  duration_text(other), share(other)),
  };
  doc.bullets(std::move(items));

  const auto* sr = c.manifest.find("solve");
  const double ours = sr && sr->duration_s > 0 ? sr->duration_s : c.solve.wall_time_s();
  if (c.paper && c.paper->run_time_s) {
    const double paper = *c.paper->run_time_s;
    doc.paragraph(fmt::format("Run time against the paper: our solve stage took {} ({}), the paper's {} on {} processes{}.",
                              duration_text(ours), sr ? "manifest.yaml" : "solve/summary.yaml", duration_text(paper),
                              c.paper->run_processes > 0 ? std::to_string(c.paper->run_processes) : std::string("?"),
                              ours > 0 ? fmt::format(": ours is {:.3g} × the paper's", ours / paper) : std::string()));
  } else if (c.paper) {
    doc.paragraph(fmt::format("Run time: our solve stage took {}; the targets give no run time for `{}`.", duration_text(ours), c.paper->key));
  }
}

void add_results_section(Document& doc, const ReportContext& c) {
  doc.heading(2, "3. Results");
  const auto& qois = c.solve.qois();
  std::set<std::string> shown;
  std::vector<std::vector<std::string>> rows;
  auto add = [&](const std::string& key, std::string meaning) {
    auto it = qois.find(key);
    if (it == qois.end()) return;
    // The paper gives pressures in atm too.
    if (auto d = std::get_if<double>(&it->second.value); d && it->second.unit == "MPa" && std::isfinite(*d))
      meaning += fmt::format(" ({:.3g} atm)", *d / units::kAtmInMPa);
    rows.push_back({key, qoi_value(it->second), it->second.unit, meaning});
    shown.insert(key);
  };
  for (const auto& k : known_results()) {
    add(k.key, k.meaning);
    if (k.key == "balloon_profile_z")
      for (const auto& [name, q] : qois)
        if (name.rfind(kProfilePrefix, 0) == 0) add(name, fmt::format("balloon diameter profile at {}", name.substr(std::string(kProfilePrefix).size())));
  }
  doc.paragraph("From `solve/summary.yaml` (the quantities the report knows, in this order; a quantity the run did not compute is not listed):");
  if (rows.empty()) doc.paragraph("None of them is in `solve/summary.yaml`.");
  else doc.table({"quantity", "value", "unit", "meaning"}, std::move(rows));

  std::vector<std::vector<std::string>> others;
  for (const auto& [name, q] : qois)
    if (!shown.count(name)) others.push_back({name, qoi_value(q), q.unit});
  if (!others.empty()) {
    doc.heading(3, "Other quantities in solve/summary.yaml");
    doc.table({"quantity", "value", "unit"}, std::move(others));
  }
  if (!c.solve_notes.empty()) {
    doc.heading(3, "Notes of the solve");
    std::vector<std::string> items;
    for (const auto& [k, v] : c.solve_notes) items.push_back(k.empty() ? v : k + ": " + v);
    doc.bullets(std::move(items));
  }
}

std::optional<TargetTable> add_targets_section(Document& doc, const ReportContext& c) {
  doc.heading(2, "4. Comparison with the paper");
  if (!c.paper) {
    doc.paragraph("This case has no paper numbers to compare with.");
    return std::nullopt;
  }
  TargetTable t = judge_targets(*c.paper, c.solve, c.in->pressure_max);
  doc.paragraph(fmt::format("Example `{}` of `workflows/report/paper_targets.yaml` (a copy of `validation/targets.yaml`). {}", c.paper->key,
                            t.pressure.statement));
  doc.paragraph(fmt::format("{} judged: {} pass, {} FAIL; {} shown but not judged; {} not computed. A tolerance is relative to the paper's "
                            "number unless it says absolute.",
                            t.judged, t.passed, t.failed, t.not_judged, t.not_computed));
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> notes;
  for (const auto& r : t.rows) {
    std::string verdict = verdict_text(r.verdict);
    if (!r.why.empty()) {
      notes.push_back(fmt::format("[{}] {}", notes.size() + 1, r.why));
      verdict += fmt::format(" [{}]", notes.size());
    }
    rows.push_back({r.quantity, r.paper, r.tolerance, r.ours, r.difference, verdict});
  }
  doc.table({"quantity", "paper", "tolerance", "ours", "difference", "verdict"}, std::move(rows));
  if (!notes.empty()) doc.bullets(std::move(notes));
  return t;
}

void add_figures_section(Document& doc, const ReportContext& c, const FigureSet& figures) {
  doc.heading(2, "5. Figures");
  if (figures.written.empty()) doc.paragraph("No figure could be drawn (see below).");
  for (const auto& f : figures.written) {
    const auto link = [&](const fs::path& p) {
      const fs::path rel = p.lexically_normal().lexically_relative(c.report_dir.lexically_normal());
      return (rel.empty() ? p : rel).generic_string();
    };
    doc.figure(f.title, f.png, link(f.png), link(f.svg), f.caption);
  }
  if (!figures.omitted.empty()) {
    doc.heading(3, "Figures not drawn");
    std::vector<std::string> items;
    for (const auto& o : figures.omitted) items.push_back(fmt::format("{}: {}", o.title, o.why));
    doc.bullets(std::move(items));
  }
}

void add_pictures_section(Document& doc, const ReportContext& c) {
  doc.heading(2, "6. 3-D pictures of the device");
  const fs::path pvd = c.in->solve_dir / "results.pvd";
  doc.paragraph(fmt::format("Not rendered by this version: the report does not link VTK, and Debian's VTK renders off-screen only "
                            "through an X server (xvfb-run). Open `{}` in ParaView and step to the frames below.",
                            shown_path(c, pvd)));
  if (!c.pvd) {
    doc.paragraph(fmt::format("`{}` is not there: the solve wrote no frames.", shown_path(c, pvd)));
    return;
  }
  if (c.pvd->empty()) {
    doc.paragraph(fmt::format("`{}` lists no frames.", shown_path(c, pvd)));
    return;
  }
  std::vector<double> times;
  for (const auto& f : *c.pvd) times.push_back(f.time);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  auto nearest = [&](double t) {
    return *std::min_element(times.begin(), times.end(), [&](double a, double b) { return std::abs(a - t) < std::abs(b - t); });
  };
  std::vector<std::vector<std::string>> rows;
  auto add_state = [&](const std::string& state, double t, const std::string& note) {
    for (const auto& f : *c.pvd)
      if (f.time == t) rows.push_back({state, num(t), f.part, shown_path(c, c.in->solve_dir / f.file), note});
  };
  add_state("initial", times.front(), "");
  const History& h = c.history;
  std::string max_note;
  if (const auto col = inflation_pressure_column(h)) {
    const std::size_t end = inflation_end(h.column(*col));
    if (end > 0) {
      const double t_max = h.column("time")[end - 1];
      const double t = nearest(t_max);
      const bool exact = std::abs(t - t_max) <= 1e-9 * std::max(1.0, std::abs(t_max));
      add_state("max (end of inflation)", t, exact ? "" : fmt::format("nearest written frame; the inflation ends at t = {}", num(t_max)));
    } else {
      max_note = fmt::format("The frame at max pressure is not known: `{}` never rises above 0.", *col);
    }
  } else {
    max_note = "The frame at max pressure is not known: `history.csv` has no inflation pressure column.";
  }
  add_state("after (last frame)", times.back(), "");
  doc.table({"state", "time", "body", "file", "note"}, std::move(rows));
  if (!max_note.empty()) doc.paragraph(max_note);
}

}  // namespace stentsim::workflows::report
