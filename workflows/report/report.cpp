#include "workflows/report/report.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "common/error.hpp"
#include "common/files.hpp"
#include "workflows/report/report_sections.hpp"

namespace fs = std::filesystem;

namespace stentsim::workflows::report {
namespace {

/// The stages the manifest has records of, in the case's order; stages it
/// does not name (an older or newer version's) after them. The report itself is still running.
std::vector<std::string> ordered_stages(const pipeline::Manifest& m, const std::vector<std::string>& order) {
  std::vector<std::string> out;
  for (const auto& s : order)
    if (s != "report" && m.find(s)) out.push_back(s);
  for (const auto& [s, r] : m.stages())
    if (s != "report" && std::find(order.begin(), order.end(), s) == order.end()) out.push_back(s);
  return out;
}

// The paper's diameters at its inflation pressure, to mark on the diameter-pressure figure.
std::vector<PaperPoint> paper_diameter_points(const PaperCase& paper) {
  std::vector<PaperPoint> pts;
  if (!paper.pressure_max) return pts;
  for (const auto& r : paper.results) {
    const TargetMapping* m = find_mapping(paper.key, r.name);
    if (m && r.value && m->summary_keys.size() == 1 && m->summary_keys.front() == "stent_diameter_max" && !m->report_only)
      pts.push_back({"paper", *paper.pressure_max, *r.value});
  }
  return pts;
}

}  // namespace

void write_report(const ReportInput& in, const fs::path& md, const fs::path& html, const fs::path& figure_dir, Summary& summary) {
  // Every input is read and checked before anything is written, so a damaged
  // input leaves no half report behind.
  ReportContext c;
  c.in = &in;
  const fs::path manifest_file = in.work_dir / "manifest.yaml";
  if (!fs::exists(manifest_file))
    throw InputError(fmt::format("{}: missing; the runner writes it after every stage", manifest_file.string()));
  c.manifest = pipeline::Manifest::load(manifest_file);
  c.stages = ordered_stages(c.manifest, in.stages);
  const fs::path solve_summary = in.solve_dir / "summary.yaml";
  c.solve = read_summary(solve_summary, "the solve stage");
  c.solve_notes = read_summary_notes(solve_summary);
  c.history = read_history(in.solve_dir / "history.csv");
  if (fs::exists(in.solve_dir / "results.pvd")) c.pvd = read_pvd(in.solve_dir / "results.pvd");
  for (const auto& s : c.stages) {
    const fs::path f = s == "solve" ? solve_summary : in.work_dir / s / "summary.yaml";
    if (s == "solve") c.stage_summaries.push_back({s, f, c.solve});
    else if (fs::exists(f)) c.stage_summaries.push_back({s, f, Summary::read(f)});
  }
  if (!in.targets_key.empty()) c.paper = paper_case(in.targets_key);
  c.report_dir = md.parent_path();

  FigureInputs fi;
  fi.history = &c.history;
  fi.solve = &c.solve;
  if (c.paper) fi.diameter_vs_pressure = paper_diameter_points(*c.paper);
  const FigureSet figures = write_figures(fi, figure_dir);

  Document doc;
  const std::string title = fmt::format("stentsim report: {}", in.case_name);
  doc.heading(1, title);
  add_case_section(doc, c, pipeline::utc_now_iso8601());
  add_run_section(doc, c);
  add_results_section(doc, c);
  const auto table = add_targets_section(doc, c);
  add_figures_section(doc, c, figures);
  add_pictures_section(doc, c);

  if (!md.parent_path().empty()) fs::create_directories(md.parent_path());
  if (!html.parent_path().empty()) fs::create_directories(html.parent_path());
  files::write_atomic(md, doc.markdown());
  files::write_atomic(html, doc.html(title));

  summary.set("report_figures", static_cast<double>(figures.written.size()));
  summary.set("report_figures_omitted", static_cast<double>(figures.omitted.size()));
  if (table) {
    summary.set("targets_passed", table->passed);
    summary.set("targets_failed", table->failed);
    summary.set("targets_judged", table->judged);
    summary.set("targets_not_judged", table->not_judged);
    summary.set("targets_not_computed", table->not_computed);
    summary.set("pressure_matches_paper", table->pressure.matches ? 1.0 : 0.0);
    summary.note("targets", in.targets_key);
  }
}

}  // namespace stentsim::workflows::report
