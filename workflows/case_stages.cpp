#include "workflows/case_stages.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "common/config.hpp"
#include "common/mesh_tags.hpp"
#include "device_gen/stages.hpp"
#include "fibers/analytic_tube_fibers.hpp"
#include "fibers/harmonic_fibers.hpp"
#include "meshing/generic_artery.hpp"
#include "meshing/patient_mesh.hpp"
#include "segmentation_io/centerline.hpp"
#include "segmentation_io/segmentation_stage.hpp"
#include "workflows/report_stage.hpp"
#include "workflows/solve_stage.hpp"

namespace stentsim::workflows {
namespace {

using pipeline::Stage;
using pipeline::StageContext;

/// The configuration text a stage depends on: the named sections, canonical.
std::string slice(const CaseConfig& c, std::initializer_list<const char*> sections) {
  std::string text = fmt::format("scene={};", to_string(c.scene));
  for (const char* s : sections) text += fmt::format("{}={};", s, canonical_yaml(c.section(s)));
  return text;
}

Stage generic_mesh_stage(const CaseConfig& c) {
  Stage s;
  s.name = "mesh";
  s.outputs = {"mesh/artery.vtu"};
  s.config = slice(c, {"mesh.generic"});
  s.version = "2";  // 2: centred on the origin, on the device's axis
  const meshing::GenericArterySpec spec = c.generic_artery;
  s.run = [spec](StageContext& ctx) {
    meshing::write_generic_artery(spec, ctx.output("mesh/artery.vtu").string(), ctx.summary());
  };
  return s;
}

/// The patient wall mesh (DESIGN.md §1): lofted layers meshed with gmsh.
Stage patient_mesh_stage(const CaseConfig& c) {
  Stage s;
  s.name = "mesh";
  s.inputs = {"segmentation/lumen.vtp", "segmentation/wall.vtp", "centerline/centerline.vtp"};
  s.outputs = {"mesh/artery.vtu", "mesh/artery.msh"};
  s.config = slice(c, {"mesh"});
  s.version = "4";  // 4: min_intima 0.05 mm (DESIGN.md §8), loft seams of neighbouring surfaces half a turn apart, 3 surface smoothing passes; 3: gmsh Delaunay (reproducible), symmetric section tangents, pre-loft section checks; 2: per-layer sizing, tet10 midside-node Jacobian check
  const meshing::PatientMeshOptions o = c.mesh;
  s.run = [o](StageContext& ctx) {
    meshing::run_patient_mesh(ctx.input("segmentation/lumen.vtp"), ctx.input("segmentation/wall.vtp"),
                              ctx.input("centerline/centerline.vtp"), o, ctx.output("mesh/artery.vtu"),
                              ctx.output("mesh/artery.msh"), ctx.summary());
  };
  return s;
}

Stage tube_fibers_stage(const CaseConfig& c) {
  Stage s;
  s.name = "fibers";
  s.inputs = {"mesh/artery.vtu"};
  s.outputs = {"fibers/fibers.vtu"};
  s.config = slice(c, {"fibers"});
  s.version = "2";  // 2: Transmural cell and point arrays
  const fibers::LayerAngles angles = {{tags::intima, c.fibers.intima_angle},
                                      {tags::media, c.fibers.media_angle},
                                      {tags::adventitia, c.fibers.adventitia_angle}};
  s.run = [angles](StageContext& ctx) {
    fibers::write_tube_fibers(ctx.input("mesh/artery.vtu").string(), angles, ctx.output("fibers/fibers.vtu").string(),
                              ctx.summary());
  };
  return s;
}

/// Patient wall: fibers by harmonic lifting on the meshed wall (fibers/harmonic_fibers.hpp).
Stage harmonic_fibers_stage(const CaseConfig& c) {
  Stage s;
  s.name = "fibers";
  s.inputs = {"mesh/artery.vtu", "centerline/centerline.vtp"};
  s.outputs = {"fibers/fibers.vtu"};
  s.config = slice(c, {"fibers"});
  s.version = "3";  // 3: tet10 t quadratic, l on the corners, recovered gradients; 2: corner solves; centerline_weight, linear_solver, laplace_on_corners keys
  fibers::HarmonicFiberOptions o;
  o.angles = {{tags::intima, c.fibers.intima_angle}, {tags::media, c.fibers.media_angle},
              {tags::adventitia, c.fibers.adventitia_angle}};
  o.centerline_weight = c.fibers.centerline_weight;
  o.linear_solver = c.fibers.linear_solver;
  o.linear_on_corners = c.fibers.laplace_on_corners;
  s.run = [o](StageContext& ctx) {
    fibers::write_harmonic_fibers(ctx.input("mesh/artery.vtu").string(), ctx.input("centerline/centerline.vtp").string(), o,
                                  ctx.output("fibers/fibers.vtu").string(), ctx.summary());
  };
  return s;
}

segmentation::SegmentationInput segmentation_input(const CaseConfig& c) {
  ConfigMap input(c.section("input"), std::make_shared<const std::filesystem::path>(c.file), "input");
  auto in = segmentation::parse_segmentation_input(input);
  in.stenosis = c.stenosis;
  return in;
}

Stage segmentation_stage(const CaseConfig& c) {
  Stage s;
  s.name = "segmentation";
  s.outputs = {"segmentation/lumen.vtp", "segmentation/wall.vtp"};
  s.config = slice(c, {"input", "stenosis"});
  s.version = "3";  // 3: input_units (the lumen_after surface is written in them); 2: wall synthesized per section by the layer rule; ROI on the stenosis rule's lesions
  const auto input = segmentation_input(c);
  if (input.is_phantom()) {
    s.outputs.push_back("segmentation/centerline_true.vtp");
  } else {
    // The user's files are external inputs: editing one makes the stage stale.
    for (const auto& f : input.input_files()) s.inputs.push_back(f.string());
  }
  s.run = [input](StageContext& ctx) {
    segmentation::run_segmentation_stage(input, ctx.output("segmentation/lumen.vtp"), ctx.output("segmentation/wall.vtp"),
                                         ctx.summary(),
                                         input.is_phantom() ? ctx.output("segmentation/centerline_true.vtp")
                                                            : std::filesystem::path());
  };
  return s;
}

Stage centerline_stage(const CaseConfig& c) {
  Stage s;
  s.name = "centerline";
  s.inputs = {"segmentation/lumen.vtp"};
  s.outputs = {"centerline/centerline.vtp"};
  s.config = slice(c, {"centerline", "stenosis"});
  s.version = "2";  // 2: lesions by the stenosis rule
  ConfigMap section(c.section("centerline"), std::make_shared<const std::filesystem::path>(c.file), "centerline");
  segmentation::CenterlineOptions options = segmentation::parse_centerline_options(section);
  options.stenosis = c.stenosis;
  // A phantom's true centerline is an input too: the stage reports its
  // accuracy against it (inscribed_radius_error_max, stenosis_site_error).
  const bool phantom = segmentation_input(c).is_phantom();
  if (phantom) s.inputs.push_back("segmentation/centerline_true.vtp");
  s.run = [options, phantom](StageContext& ctx) mutable {
    if (phantom) options.true_centerline = ctx.input("segmentation/centerline_true.vtp");
    segmentation::run_centerline_stage(options, ctx.input("segmentation/lumen.vtp"),
                                       ctx.output("centerline/centerline.vtp"), ctx.summary());
  };
  return s;
}

ConfigMap section_map(const CaseConfig& c, const std::string& dotted) {
  return ConfigMap(c.section(dotted), std::make_shared<const std::filesystem::path>(c.file), dotted);
}

struct DeviceDesign {
  device_gen::BalloonDesign balloon;
  device_gen::StentDesign stent;
};

DeviceDesign device_design(const CaseConfig& c) {
  auto b = section_map(c, "device.balloon");
  auto st = section_map(c, "device.stent");
  return {device_gen::parse_balloon_design(b), device_gen::parse_stent_design(st)};
}

Stage placement_stage(const CaseConfig& c) {
  Stage s;
  s.name = "placement";
  s.inputs = {"centerline/centerline.vtp", "segmentation/lumen.vtp"};
  s.outputs = {"placement/placement.yaml", "placement/balloon_centerline.vtp"};
  // Placement uses the balloon length and the stent's length and envelope too.
  s.config = slice(c, {"device", "stenosis"});
  s.version = "2";  // 2: the site is the most severe lesion of the stenosis rule
  auto p = section_map(c, "device.placement");
  auto params = device_gen::parse_placement_params(p);
  params.stenosis = c.stenosis;
  const auto d = device_design(c);
  s.run = [params, d](StageContext& ctx) {
    device_gen::run_placement_stage(params, ctx.input("centerline/centerline.vtp"), ctx.input("segmentation/lumen.vtp"),
                                    d.balloon, d.stent, ctx.output("placement/placement.yaml"),
                                    ctx.output("placement/balloon_centerline.vtp"), ctx.summary());
  };
  return s;
}

/// Balloon or stent: along the placement's balloon centerline in a patient or
/// a curved free expansion, straight along +z otherwise (DESIGN.md §3).
Stage device_stage(const CaseConfig& c, const std::string& name) {
  Stage s;
  s.name = name;
  const bool placed = c.placed;
  if (placed) s.inputs = {"placement/placement.yaml"};
  s.outputs = {name + "/" + name + ".vtu"};
  // Placed or straight is part of what the stage computes: a curved free
  // expansion that loses its input must not keep its warped device.
  s.config = slice(c, {name == "balloon" ? "device.balloon" : "device.stent"}) + (placed ? "placed;" : "straight;");
  s.version = "1";
  const auto d = device_design(c);
  s.run = [d, name, placed](StageContext& ctx) {
    std::optional<std::filesystem::path> placement;
    if (placed) placement = ctx.input("placement/placement.yaml");
    const auto out = ctx.output(name + "/" + name + ".vtu");
    if (name == "balloon") device_gen::run_balloon_stage(d.balloon, placement, out, ctx.summary());
    else device_gen::run_stent_stage(d.stent, placement, out, ctx.summary());
  };
  return s;
}

}  // namespace

const std::vector<std::string>& all_stage_names() {
  static const std::vector<std::string> names = {"segmentation", "centerline", "placement", "balloon", "stent",
                                                 "mesh",         "fibers",     "solve",     "report"};
  return names;
}

std::vector<pipeline::Stage> stages_for(const CaseConfig& c) {
  std::vector<pipeline::Stage> stages;
  switch (c.scene) {
    case Scene::free_expansion:
      if (c.placed) {  // the curved device: along the input vessel's centerline, no artery
        stages.push_back(segmentation_stage(c));
        stages.push_back(centerline_stage(c));
        stages.push_back(placement_stage(c));
      }
      stages.push_back(device_stage(c, "balloon"));
      stages.push_back(device_stage(c, "stent"));
      break;
    case Scene::generic_artery:
      stages.push_back(device_stage(c, "balloon"));
      stages.push_back(device_stage(c, "stent"));
      stages.push_back(generic_mesh_stage(c));
      stages.push_back(tube_fibers_stage(c));
      break;
    case Scene::patient:
      stages.push_back(segmentation_stage(c));
      stages.push_back(centerline_stage(c));
      stages.push_back(placement_stage(c));
      stages.push_back(device_stage(c, "balloon"));
      stages.push_back(device_stage(c, "stent"));
      stages.push_back(patient_mesh_stage(c));
      break;
  }
  // The patient's fibers need the wall mesh: added right after the stage that
  // produces it (design order: mesh, fibers, solve), once there is one.
  const auto wall_mesh = std::find_if(stages.begin(), stages.end(), [](const Stage& s) {
    return std::find(s.outputs.begin(), s.outputs.end(), "mesh/artery.vtu") != s.outputs.end();
  });
  if (c.scene == Scene::patient && wall_mesh != stages.end()) stages.insert(wall_mesh + 1, harmonic_fibers_stage(c));
  stages.push_back(solve_stage(c));
  stages.push_back(report_stage(c));
  return stages;
}

}  // namespace stentsim::workflows
