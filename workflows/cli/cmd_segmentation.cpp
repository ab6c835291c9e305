// `stentsim phantom` and `stentsim centerline`: the first two stages as tools
// of their own.
#include <cstdio>

#include "common/config.hpp"
#include "common/summary.hpp"
#include "segmentation_io/centerline.hpp"
#include "segmentation_io/phantom.hpp"
#include "segmentation_io/segmentation_stage.hpp"
#include "segmentation_io/surface_input.hpp"
#include "workflows/cli/commands.hpp"

namespace stentsim::cli {

void register_segmentation(CLI::App& app) {
  struct PhantomArgs {
    std::string preset, out;
    unsigned seed = 1;
  };
  auto p = std::make_shared<PhantomArgs>();
  auto* phantom = app.add_subcommand("phantom", "Write a synthetic patient: lumen.vtp, wall.vtp, centerline_true.vtp");
  phantom->add_option("--preset", p->preset, "Preset")->required()->check(CLI::IsMember(segmentation::phantom_preset_names()));
  phantom->add_option("--seed", p->seed, "Seed (deterministic output per seed)");
  phantom->add_option("--out", p->out, "Output folder")->required();
  on(phantom, [p] {
    Summary summary;
    segmentation::write_phantom(segmentation::phantom_preset(p->preset, p->seed), p->out, summary);
    summary.write(std::filesystem::path(p->out) / "summary.yaml");
    std::printf("wrote %s/{lumen,wall,centerline_true}.vtp\n", p->out.c_str());
    return 0;
  });

  // The segmentation stage alone: a case file (its `input:` section) or a
  // file holding just an input section, e.g. {simvascular: {path, lumen}}.
  struct SegmentArgs {
    std::string input, out;
  };
  auto g = std::make_shared<SegmentArgs>();
  auto* seg = app.add_subcommand(
      "segmentation", "Make lumen.vtp and wall.vtp from a case's input (phantom, surface, simvascular, label_image)");
  seg->add_option("INPUT", g->input, "Case file, or a YAML file holding one input section")->required();
  seg->add_option("--out", g->out, "Output folder")->required();
  on(seg, [g] {
    ConfigMap root = ConfigMap::load(g->input);
    ConfigMap input = root.has("input") ? root.map("input") : root;
    segmentation::SegmentationInput in = segmentation::parse_segmentation_input(input);
    std::filesystem::create_directories(g->out);
    const std::filesystem::path out(g->out);
    Summary summary;
    segmentation::run_segmentation_stage(in, out / "lumen.vtp", out / "wall.vtp", summary,
                                         in.is_phantom() ? out / "centerline_true.vtp" : std::filesystem::path());
    summary.write(out / "summary.yaml");
    std::printf("wrote %s/{lumen,wall}.vtp\n", g->out.c_str());
    return 0;
  });

  struct CenterlineArgs {
    std::string lumen, out, truth, units = "mm";
    double spacing = 0.1;
  };
  auto c = std::make_shared<CenterlineArgs>();
  auto* cl = app.add_subcommand("centerline", "Compute the lumen centerline (VMTK arrays) of a lumen surface");
  cl->add_option("--lumen", c->lumen, "Lumen surface (.vtp, .vtk, .stl or .obj; two open ends)")->required();
  cl->add_option("--units", c->units, "Units of the lumen file's coordinates")->check(CLI::IsMember({"mm", "cm", "m", "um"}));
  cl->add_option("--out", c->out, "Output centerline.vtp")->required();
  cl->add_option("--spacing", c->spacing, "Resampling spacing in mm")
      ->check(CLI::Range(segmentation::kMinCenterlineSpacing, segmentation::kMaxCenterlineSpacing));
  cl->add_option("--true-centerline", c->truth, "A phantom's centerline_true.vtp to report accuracy against");
  on(cl, [c] {
    segmentation::CenterlineOptions o;
    o.spacing = c->spacing;
    if (!c->truth.empty()) o.true_centerline = c->truth;
    Summary summary;
    // The case path's reader (by extension) and surface checks: a damaged or mis-scaled
    // file is an error here too, not a centerline of garbage.
    segmentation::SurfaceCheckOptions checks;
    checks.units = c->units;
    checks.units_key = "--units";
    segmentation::SurfaceReport report;
    const segmentation::TriSurface lumen = segmentation::load_checked_surface(c->lumen, checks, report);
    segmentation::report_to_summary("lumen", report, summary);
    // The case path's units rule too: a lumen whose healthy diameter is no coronary's in
    // the declared units (a file in cm read as mm) is refused before anything is written.
    segmentation::run_centerline_stage(o, segmentation::mesh_from_surface(lumen), c->lumen, c->out, summary,
                                       [&](const segmentation::CenterlineResult& r) {
                                         segmentation::check_reference_diameter_units(
                                             segmentation::robust_reference_diameter(r.stenoses), c->units, c->lumen,
                                             "--units");
                                       });
    summary.write(std::filesystem::path(c->out).parent_path() / "summary.yaml");
    return 0;
  });
}

}  // namespace stentsim::cli
