#include "workflows/report_stage.hpp"

#include <fmt/format.h>

#include "common/config.hpp"
#include "workflows/case_stages.hpp"
#include "workflows/report/report.hpp"

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

}  // namespace

pipeline::Stage report_stage(const CaseConfig& c) {
  pipeline::Stage s;
  s.name = "report";
  s.inputs = {"solve/summary.yaml", "solve/history.csv", "solve/results.pvd"};
  s.outputs = {"report/report.md", "report/report.html", "report/figures/"};
  s.config = fmt::format("scene={};name={};simulation={}", to_string(c.scene), c.name, canonical_yaml(c.section("simulation")));
  s.version = "1";
  report::ReportInput in;
  in.case_name = c.name;
  in.scene = to_string(c.scene);
  in.case_file = c.file;
  in.targets_key = targets_key(c);
  in.pressure_max = c.simulation.pressure_max;
  in.stages = all_stage_names();
  s.run = [in](pipeline::StageContext& ctx) mutable {
    in.work_dir = ctx.work_dir();
    in.solve_dir = ctx.input("solve/summary.yaml").parent_path();
    report::write_report(in, ctx.output("report/report.md"), ctx.output("report/report.html"),
                         ctx.output("report/figures/"), ctx.summary());
  };
  return s;
}

}  // namespace stentsim::workflows
