#include "workflows/report_stage.hpp"

#include <fmt/format.h>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/summary.hpp"
#include "workflows/case_stages.hpp"
#include "workflows/lumen_export.hpp"
#include "workflows/report/report.hpp"
#include "workflows/report/report_inputs.hpp"

namespace stentsim::workflows {

namespace {

/// The entry of the paper's numbers (targets.yaml) that this case reproduces, if any.
std::string targets_key(const CaseConfig& c) {
  switch (c.scene) {
    case Scene::free_expansion: return c.placed ? "free_expansion_curved" : "free_expansion_straight";
    case Scene::generic_artery: return "generic_artery_case1";
    case Scene::patient: return "patient_case2";
  }
  return "";
}

/// The deformed lumen after deflation (the solve's last artery frame) for a flow
/// simulation, in the input's units (segmentation/summary.yaml input_units; mm
/// for a generated artery).
void write_lumen_after(const std::filesystem::path& solve_dir, bool segmented, pipeline::StageContext& ctx) {
  const auto frames = report::read_pvd(solve_dir / "results.pvd");
  const report::PvdFrame* last = nullptr;
  for (const auto& f : frames)
    if (f.part == "artery" && (!last || f.time >= last->time)) last = &f;
  if (!last) throw InputError(fmt::format("{}: no artery frame to take the lumen after deflation from", (solve_dir / "results.pvd").string()));
  std::string units = "mm";
  if (segmented) {
    const std::filesystem::path seg = ctx.input("segmentation/summary.yaml");
    const Summary s = report::read_summary(seg, "the segmentation stage");
    const auto it = s.qois().find("input_units");
    const std::string* text = it == s.qois().end() ? nullptr : std::get_if<std::string>(&it->second.value);
    if (!text) throw InputError(fmt::format("{}: no input_units (written by the segmentation stage since its version 3): run the "
                                            "segmentation stage again (stentsim run re-runs it)", seg.string()));
    units = *text;
  }
  const MeshData lumen = deformed_lumen(solve_dir / last->file, units);
  write_lumen(lumen, ctx.output("report/lumen_after.vtp"), ctx.output("report/lumen_after.stl"));
  ctx.summary().set("lumen_after_triangles", static_cast<double>(lumen.num_cells()));
  ctx.summary().set_text("lumen_after_units", units);
  ctx.summary().set("lumen_after_time", last->time);
}

}  // namespace

pipeline::Stage report_stage(const CaseConfig& c) {
  pipeline::Stage s;
  s.name = "report";
  s.inputs = {"solve/summary.yaml", "solve/history.csv", "solve/results.pvd"};
  s.outputs = {"report/report.md", "report/report.html", "report/figures/"};
  const bool artery = c.scene != Scene::free_expansion;
  if (artery) {
    s.outputs.push_back("report/lumen_after.vtp");
    s.outputs.push_back("report/lumen_after.stl");
  }
  const bool segmented = c.scene == Scene::patient || c.placed;  // scenes with a segmentation stage
  if (artery && segmented) s.inputs.push_back("segmentation/summary.yaml");  // input_units of lumen_after
  s.config = fmt::format("scene={};name={};simulation={}", to_string(c.scene), c.name, canonical_yaml(c.section("simulation")));
  s.version = "2";  // 2: lumen_after.vtp/.stl
  report::ReportInput in;
  in.case_name = c.name;
  in.scene = to_string(c.scene);
  in.case_file = c.file;
  in.targets_key = targets_key(c);
  in.pressure_max = c.simulation.pressure_max;
  in.stages = all_stage_names();
  s.run = [in, artery, segmented](pipeline::StageContext& ctx) mutable {
    in.work_dir = ctx.work_dir();
    in.solve_dir = ctx.input("solve/summary.yaml").parent_path();
    report::write_report(in, ctx.output("report/report.md"), ctx.output("report/report.html"),
                         ctx.output("report/figures/"), ctx.summary());
    if (artery) write_lumen_after(in.solve_dir, segmented, ctx);
  };
  return s;
}

}  // namespace stentsim::workflows
