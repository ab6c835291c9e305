#include "workflows/case_config.hpp"

#include <fmt/format.h>

#include <numbers>
#include <sstream>

#include "common/config.hpp"
#include "common/error.hpp"
#include "solver/linalg/linear_solver_config.hpp"
#include "workflows/case_sections.hpp"

namespace stentsim::workflows {

const char* to_string(Scene s) {
  switch (s) {
    case Scene::free_expansion: return "free-expansion";
    case Scene::generic_artery: return "generic-artery";
    case Scene::patient: return "patient";
  }
  return "";
}

YAML::Node CaseConfig::section(const std::string& dotted) const {
  YAML::Node n = YAML::Clone(root);
  std::stringstream ss(dotted);
  std::string part;
  while (std::getline(ss, part, '.')) {
    if (!n.IsMap() || !n[part]) return YAML::Node(YAML::NodeType::Map);
    n = n[part];
  }
  return n;
}

namespace {

MeshSettings parse_mesh(ConfigMap m, meshing::GenericArterySpec& generic) {
  MeshSettings s;
  s.element = m.choice("element", {"tet10", "tet4"}, s.element);
  s.size = m.quantity("size", units::kLength, s.size, Range::positive());
  s.min_elements_per_layer = m.integer("min_elements_per_layer", s.min_elements_per_layer, Range::between(1, 20));
  s.media_ratio = m.number("media_ratio", s.media_ratio, Range::between(0, 0.5));
  s.adventitia_ratio = m.number("adventitia_ratio", s.adventitia_ratio, Range::between(0, 0.5));
  s.min_intima = m.quantity("min_intima", units::kLength, s.min_intima, Range::non_negative());
  s.min_scaled_jacobian = m.number("min_scaled_jacobian", s.min_scaled_jacobian, Range::between(0, 1));
  s.min_size_ratio = m.number("min_size_ratio", s.min_size_ratio, Range::between(0.01, 1));
  s.intima = m.boolean("intima", s.intima);
  s.station_spacing = m.quantity("station_spacing", units::kLength, s.station_spacing, Range::positive());
  s.points_per_section = m.integer("points_per_section", s.points_per_section, Range::between(8, 512));
  s.end_trim = m.quantity("end_trim", units::kLength, s.end_trim, Range::non_negative());
  s.max_aspect_ratio = m.number("max_aspect_ratio", s.max_aspect_ratio, Range::between(1, 1e6));
  s.min_section_gap_ratio = m.number("min_section_gap_ratio", s.min_section_gap_ratio, Range::between(0, 0.99));
  s.algorithm_3d = m.choice("algorithm_3d", {"delaunay", "hxt"}, s.algorithm_3d);  // hxt: not reproducible (gmsh 4.8)
  s.max_elements = m.number("max_elements", s.max_elements, Range{1.0, 1e9});
  if (s.media_ratio + s.adventitia_ratio >= 0.5) m.fail("adventitia_ratio", "media_ratio + adventitia_ratio must be below 0.5");
  if (!s.intima && s.media_ratio == 0 && s.adventitia_ratio == 0) m.fail("intima", "at least one layer is needed");
  if (auto g = m.optional_map("generic")) {
    generic.length = g->quantity("length", units::kLength, generic.length, Range::positive());
    generic.outer_diameter = g->quantity("outer_diameter", units::kLength, generic.outer_diameter, Range::positive());
    generic.media_thickness = g->quantity("media_thickness", units::kLength, generic.media_thickness, Range::positive());
    generic.adventitia_thickness =
        g->quantity("adventitia_thickness", units::kLength, generic.adventitia_thickness, Range::positive());
    generic.elements_around = g->integer("elements_around", generic.elements_around, Range::between(8, 4096));
    generic.elements_along = g->integer("elements_along", generic.elements_along, Range::between(1, 100000));
    generic.elements_media = g->integer("elements_media", generic.elements_media, Range::between(1, 100));
    generic.elements_adventitia = g->integer("elements_adventitia", generic.elements_adventitia, Range::between(1, 100));
    if (2 * (generic.media_thickness + generic.adventitia_thickness) >= generic.outer_diameter)
      g->fail("", "media_thickness + adventitia_thickness must be less than outer_diameter / 2");
    const double hexes = double(generic.elements_around) * generic.elements_along *
                         (generic.elements_media + generic.elements_adventitia);
    if (hexes > s.max_elements)
      g->fail("elements_along", fmt::format("{} around x {} along x {} through = {:.3g} hex8, more than mesh.max_elements = "
                                            "{:.3g}; lower the counts or raise mesh.max_elements", generic.elements_around,
                                            generic.elements_along, generic.elements_media + generic.elements_adventitia,
                                            hexes, s.max_elements));
    g->finish();
  }
  m.finish();
  return s;
}

FiberSettings parse_fibers(ConfigMap m) {
  FiberSettings s;
  const Range angle = Range::between(-std::numbers::pi / 2, std::numbers::pi / 2);
  s.media_angle = m.quantity("media_angle", units::kAngle, s.media_angle, angle);
  s.intima_angle = m.quantity("intima_angle", units::kAngle, s.intima_angle, angle);
  s.adventitia_angle = m.quantity("adventitia_angle", units::kAngle, s.adventitia_angle, angle);
  s.tension_only = m.boolean("tension_only", s.tension_only);
  s.centerline_weight = m.number("centerline_weight", s.centerline_weight, Range::between(0, 1));
  s.linear_solver = solver::read_linear_solver(m, "linear_solver", s.linear_solver);
  s.laplace_on_corners = m.boolean("laplace_on_corners", s.laplace_on_corners);
  m.finish();
  return s;
}

SimulationSettings parse_simulation(ConfigMap m) {
  SimulationSettings s;
  s.pressure_max = m.quantity("pressure_max", units::kPressure, s.pressure_max, Range{0.0, 10.0, false, true});
  s.diastolic_pressure = m.quantity("diastolic_pressure", units::kPressure, s.diastolic_pressure, Range::between(0, 0.1));
  s.phase_duration = m.quantity("phase_duration", units::kTime, s.phase_duration, Range::positive());
  s.load_steps = m.integer("load_steps", s.load_steps, Range::between(1, 100000));
  s.min_load_steps = m.integer("min_load_steps", s.min_load_steps, Range::between(0, 100000));
  if (s.min_load_steps > s.load_steps)
    m.fail("min_load_steps", fmt::format("must be at most load_steps ({}): the step grows from phase / load_steps up to "
                                         "phase / min_load_steps (0: it never grows)", s.load_steps));
  s.linear_solver = solver::read_linear_solver(m, "linear_solver", s.linear_solver);
  s.ranks = m.integer("ranks", s.ranks, Range::between(1, 4096));
  if (s.ranks > 1 && solver::one_rank_only(s.linear_solver))
    m.fail("ranks", fmt::format("linear_solver {} runs on one MPI rank in this version; set ranks: 1, or "
                                "linear_solver gmres_ilu (direct: the whole system's LU, far more memory) for {} ranks",
                                solver::linear_solver_name(s.linear_solver), s.ranks));
  s.balloon_end_springs = m.quantity("balloon_end_springs", units::kStiffnessPerArea, s.balloon_end_springs, Range::positive());
  s.cut_springs = m.quantity("cut_springs", units::kStiffnessPerArea, s.cut_springs, Range::positive());
  s.beam_penalty = m.quantity("beam_penalty", units::kPressure, s.beam_penalty, Range::positive());
  s.surface_penalty = m.quantity("surface_penalty", units::kStiffnessPerArea, s.surface_penalty, Range::positive());
  m.finish();
  return s;
}

OutputSettings parse_output(ConfigMap m) {
  OutputSettings s;
  s.every = m.integer("every", s.every, Range::between(1, 1000000));
  s.checkpoint_every = m.integer("checkpoint_every", s.checkpoint_every, Range::between(0, 1000000));
  m.finish();
  return s;
}

}  // namespace

CaseConfig load_case(const std::filesystem::path& file) {
  ConfigMap top = ConfigMap::load(file);
  CaseConfig c;
  c.file = std::filesystem::absolute(file).lexically_normal();
  c.root = top.node();
  c.name = top.string("name", file.stem().string());
  const std::string scene = top.choice("scene", {"free-expansion", "generic-artery", "patient"});
  c.scene = scene == "free-expansion" ? Scene::free_expansion : scene == "generic-artery" ? Scene::generic_artery : Scene::patient;
  c.work_dir = top.path("work_dir", std::filesystem::path(file.stem().string() + ".work"));
  // The work folder holds the manifest, lock and logs: it must not be the
  // case's own folder or one of its ancestors.
  const auto up = c.file.parent_path().lexically_relative(c.work_dir);
  if (up.empty() || up == "." || up.native().rfind("..", 0) != 0)
    top.fail("work_dir", "must be a folder of its own (e.g. 'case.work'), not the case file's folder or above it");
  if (std::filesystem::exists(c.work_dir) && !std::filesystem::is_directory(c.work_dir))
    top.fail("work_dir", "'" + c.work_dir.string() + "' exists and is not a folder");
  c.mesh = parse_mesh(top.map("mesh"), c.generic_artery);
  c.fibers = parse_fibers(top.map("fibers"));
  c.simulation = parse_simulation(top.map("simulation"));
  c.output = parse_output(top.map("output"));
  c.placed = c.scene == Scene::patient || (c.scene == Scene::free_expansion && top.has("input"));
  if (top.has("stenosis") && !c.placed)
    top.fail("stenosis", c.scene == Scene::free_expansion
                             ? "a free-expansion scene without an input has no lumen to find lesions in; remove this section, or "
                               "add an input: to place the device along a vessel (the curved device)"
                             : "a generic-artery scene has no lumen to find lesions in; remove this section");
  {
    auto st = top.map("stenosis");
    c.stenosis = parse_stenosis_rule(st);
  }
  // Input and device sections are validated by the parsers of the stages
  // that read them (case_sections.cpp), so a bad key fails before any run.
  validate_stage_sections(c, top);
  top.finish();
  return c;
}

}  // namespace stentsim::workflows
