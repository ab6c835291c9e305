#include "solver/io/scene.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <numbers>
#include <set>
#include <sstream>

#include "common/error.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/materials/presets.hpp"

namespace stentsim::solver {
namespace {

Vec3 vec3(ConfigMap& m, const std::string& key, std::optional<Vec3> def = std::nullopt) {
  std::optional<std::vector<double>> d;
  if (def) d = std::vector<double>{def->x(), def->y(), def->z()};
  const auto v = m.numbers(key, 3, d);
  return {v[0], v[1], v[2]};
}

MeshData read_mesh(ConfigMap& m, std::string& source) {
  const bool has_file = m.has("file"), has_gen = m.has("generate");
  if (has_file == has_gen) m.fail("", "give exactly one of 'file' (a .vtu) or 'generate'");
  if (has_file) {
    const auto path = m.path("file");
    source = path.string();
    if (path.extension() != ".vtu") m.fail("file", "expected a .vtu file");
    return read_vtu(path.string());
  }
  ConfigMap g = m.map("generate");
  const std::string type = g.choice("type", {"ring_sector", "box"});
  const std::string element = g.choice("element", {"hex8", "tet4", "tet10"}, "hex8");
  // tet10 midside nodes: on straight edges, or (ring sector) on the exact cylinders.
  const std::string midside = g.choice("midside", {"straight", "cylinder"}, "straight");
  if (midside == "cylinder" && (type != "ring_sector" || element != "tet10"))
    g.fail("midside", "'cylinder' places tet10 midside nodes on a ring sector's cylinders; needs type: ring_sector and element: tet10");
  MeshData mesh;
  if (type == "ring_sector") {
    const double ri = g.quantity("inner_radius", units::kLength, std::nullopt, Range::positive());
    const double ro = g.quantity("outer_radius", units::kLength, std::nullopt, Range::positive());
    if (ro <= ri) g.fail("outer_radius", "must exceed inner_radius");
    const double angle = g.number("angle_deg", 360.0, Range{0.0, 360.0, false, true});
    const double height = g.quantity("height", units::kLength, std::nullopt, Range::positive());
    const int nr = g.integer("radial", std::nullopt, Range{1.0, 1e4});
    const int nt = g.integer("circumferential", std::nullopt, Range{1.0, 1e5});
    const int nz = g.integer("axial", 1, Range{1.0, 1e5});
    if (angle == 360.0) g.fail("angle_deg", "a closed ring is not generated (duplicate seam nodes); use < 360 with symmetry conditions");
    mesh = ring_sector_hex8(ri, ro, angle * std::numbers::pi / 180.0, height, nr, nt, nz);
    source = fmt::format("generated ring sector {}x{}x{} {}", nr, nt, nz, element);
  } else {
    const auto size = g.numbers("size", 3);
    const auto cells = g.numbers("cells", 3);
    mesh = box_hex8(static_cast<int>(cells[0]), static_cast<int>(cells[1]), static_cast<int>(cells[2]), size[0], size[1], size[2]);
    source = fmt::format("generated box {}x{}x{} {}", cells[0], cells[1], cells[2], element);
  }
  if (element != "hex8") {
    auto pd = mesh.point_data;
    mesh = hex8_to_tet4(mesh);
    if (element == "tet10") mesh = midside == "cylinder" ? tet4_to_tet10_cylindrical(mesh) : tet4_to_tet10(mesh);
    else mesh.point_data = pd;
  }
  g.finish();
  return mesh;
}

Material read_material(ConfigMap& m) {
  Material mat;
  if (m.has("preset")) {
    const std::string p = m.choice("preset", material_preset_names());
    mat = material_preset(p);
  }
  mat.name = m.string("name", mat.name.empty() ? std::string("material") : mat.name);
  if (auto nh = m.optional_map("neo_hooke")) {
    const double e = nh->quantity("E", units::kPressure, std::nullopt, Range::positive());
    const double nu = nh->number("nu", std::nullopt, Range{-1.0, 0.5, false, false});
    mat.matrix = CoupledNeoHooke::from_young_poisson(e, nu);
    nh->finish();
  }
  if (m.has("fibers")) {
    mat.fibers.clear();
    for (auto& f : m.map_list("fibers")) {
      FiberFamilySpec s;
      s.law.k1 = f.quantity("k1", units::kPressure, std::nullopt, Range::non_negative());
      s.law.k2 = f.number("k2", std::nullopt, Range::non_negative());
      s.law.tension_only = f.boolean("tension_only", false);
      s.law.multiplicity = f.number("count", 1.0, Range::positive());
      if (f.has("direction")) s.global_direction = vec3(f, "direction").normalized();
      else s.angle_deg = f.number("angle_deg", 0.0, Range::between(-180, 180));
      f.finish();
      mat.fibers.push_back(s);
    }
  }
  if (m.has("tension_only_fibers")) {
    const bool t = m.boolean("tension_only_fibers");
    for (auto& f : mat.fibers) f.law.tension_only = t;
  }
  if (auto v = m.optional_map("viscous")) {
    const bool on = v->boolean("enabled", true);
    if (on) mat.viscous = ViscousBranch{v->quantity("tau", units::kTime, 0.5, Range::positive()), v->number("beta", 0.3, Range::non_negative())};
    else mat.viscous.reset();
    v->finish();
  }
  if (!mat.matrix && mat.fibers.empty()) m.fail("", "a material needs a 'preset', 'neo_hooke' or 'fibers'");
  if (static_cast<int>(mat.fibers.size()) > kMaxFiberFamilies)
    m.fail("fibers", fmt::format("at most {} fiber families", kMaxFiberFamilies));
  return mat;
}

}  // namespace

SceneDesc read_scene(const std::filesystem::path& file) {
  ConfigMap root = ConfigMap::load(file);
  SceneDesc scene;
  scene.file = file;
  scene.description = root.string("description", "");

  std::set<std::string> names, beam_names;
  for (auto& b : root.map_list("bodies")) {
    BodyDesc body;
    body.name = b.string("name");
    if (!names.insert(body.name).second) b.fail("name", fmt::format("body name '{}' is used twice", body.name));
    if (b.has("beam") == b.has("mesh")) b.fail("", "a body needs exactly one of 'mesh' (a solid) or 'beam'");
    if (b.has("beam")) {
      ConfigMap beam = b.map("beam");
      body.beam = beams::read_beam_body(beam);
      beam.finish();
      body.mesh_source = body.beam->source;
      b.finish();
      beam_names.insert(body.name);
      scene.bodies.push_back(std::move(body));
      continue;
    }
    ConfigMap mesh = b.map("mesh");
    body.mesh = read_mesh(mesh, body.mesh_source);
    mesh.finish();
    body.tag_array = b.string("material_array", "");
    if (!body.tag_array.empty() && !body.mesh.cell_data.count(body.tag_array))
      b.fail("material_array", fmt::format("the mesh ({}) has no cell array '{}'", body.mesh_source, body.tag_array));
    for (auto& m : b.map_list("materials")) {
      const int tag = m.integer("tag", 0);
      if (body.materials.count(tag)) m.fail("tag", fmt::format("tag {} is given twice", tag));
      body.materials[tag] = read_material(m);
      m.finish();
    }
    if (body.materials.empty()) b.fail("materials", "at least one material is required");
    if (body.tag_array.empty() && body.materials.size() != 1)
      b.fail("material_array", "several materials need a cell array that tags the cells");
    if (auto f = b.optional_map("fiber_frames")) {
      if (auto c = f->optional_map("cylindrical")) {
        body.frames.kind = FrameSource::Kind::cylindrical;
        body.frames.origin = vec3(*c, "origin", Vec3::Zero());
        body.frames.axis = vec3(*c, "axis", Vec3::UnitZ()).normalized();
        c->finish();
      } else if (f->has("file")) {
        body.frames.kind = FrameSource::Kind::file;
        body.frames.file = f->path("file");
        body.frames.radial = f->string("radial", body.frames.radial);
        body.frames.circumferential = f->string("circumferential", body.frames.circumferential);
        body.frames.longitudinal = f->string("longitudinal", body.frames.longitudinal);
        // Words: the fiber arrays for families 1, 2, ... ("Fiber1 Fiber2", the fibers stage's), or "none".
        if (f->has("fibers")) {
          std::istringstream words(f->string("fibers"));
          body.frames.fibers.clear();
          for (std::string w; words >> w;)
            if (w != "none") body.frames.fibers.push_back(w);
          if (static_cast<int>(body.frames.fibers.size()) > kMaxFiberFamilies)
            f->fail("fibers", fmt::format("at most {} fiber arrays (one per family)", kMaxFiberFamilies));
        }
      } else {
        b.fail("fiber_frames", "expected 'cylindrical: {origin, axis}' or 'file: fibers.vtu'");
      }
      f->finish();
    }
    b.finish();
    scene.bodies.push_back(std::move(body));
  }
  if (scene.bodies.empty()) root.fail("bodies", "at least one body is required");

  if (root.has("load_curves")) {
    ConfigMap lc = root.map("load_curves");
    for (const auto& kv : lc.node()) {
      const std::string name = kv.first.Scalar();
      std::vector<std::pair<double, double>> pts;
      bool ok = kv.second.IsSequence() && kv.second.size() > 0;
      if (ok)
        for (const auto& p : kv.second) {
          if (!p.IsSequence() || p.size() != 2) { ok = false; break; }
          try {
            pts.emplace_back(p[0].as<double>(), p[1].as<double>());
          } catch (const YAML::Exception&) { ok = false; break; }
        }
      if (!ok) lc.fail(name, "expected a list of [time, factor] pairs");
      try {
        scene.curves[name] = LoadCurve(pts);
      } catch (const std::invalid_argument& e) {
        lc.fail(name, e.what());
      }
    }
  }
  auto check_curve = [&](ConfigMap& c, const std::string& name) {
    if (!name.empty() && !scene.curves.count(name))
      c.fail("curve", fmt::format("no load curve named '{}' in load_curves", name));
  };
  auto check_body = [&](ConfigMap& c, const std::string& name) {
    if (!names.count(name)) c.fail("body", fmt::format("no body named '{}'", name));
  };
  // Solid conditions/QoIs need a solid body, beam ones a beam body.
  auto check_kind = [&](ConfigMap& c, const std::string& name, bool beam, const std::string& type) {
    if (beam_names.count(name) != static_cast<std::size_t>(beam))
      c.fail("body", fmt::format("'{}' applies to {} bodies; '{}' is a {} body", type, beam ? "beam" : "solid", name,
                                 beam_names.count(name) ? "beam" : "solid"));
  };
  auto beam_body = [&](const std::string& name) -> const beams::BeamBodyDesc& {
    for (const auto& b : scene.bodies)
      if (b.name == name) return *b.beam;
    throw std::logic_error("beam body lookup");
  };
  // A beam node selection must select something (file:line of the key).
  auto check_nodes = [&](ConfigMap& c, const std::string& body, const beams::BeamNodeSelector& sel) {
    std::vector<int> nodes;
    try {
      nodes = beams::select_beam_nodes(beam_body(body), sel);
    } catch (const InputError& e) {
      c.fail("node", e.what());
    }
    if (nodes.empty()) c.fail("node", fmt::format("selects no end node of beam body '{}' ({})", body, sel.describe()));
  };
  // Cylindrical beam conditions: `axis: {origin, direction}` (default the z axis).
  auto read_axis = [&](ConfigMap& c, ConditionDesc& d) {
    if (auto ax = c.optional_map("axis")) {
      d.axis_origin = vec3(*ax, "origin", Vec3::Zero());
      d.axis = vec3(*ax, "direction", Vec3::UnitZ());
      if (!(d.axis.norm() > 0)) ax->fail("direction", "must be a non-zero vector");
      d.axis.normalize();
      ax->finish();
    }
  };
  std::map<std::string, std::string> radial_conditions;  // radial_displacement name -> body (for release)
  std::set<std::string> released;

  int index = 0;
  for (auto& c : root.map_list("conditions")) {
    ConditionDesc d;
    const std::string type =
        c.choice("type", {"pressure", "springs", "dirichlet", "clamp", "point_force", "point_moment", "direction",
                          "radial_displacement", "fix_cylindrical", "release"});
    d.name = c.string("name", fmt::format("{}_{}", type, index++));
    for (const auto& other : scene.conditions)
      if (other.name == d.name) c.fail("name", fmt::format("condition name '{}' is used twice", d.name));
    d.body = c.string("body");
    check_body(c, d.body);
    const bool beam_type = type == "clamp" || type == "point_force" || type == "point_moment" || type == "direction" ||
                           type == "radial_displacement" || type == "fix_cylindrical" || type == "release";
    check_kind(c, d.body, beam_type, type);
    if (type == "release") {
      // The radial conditions become point forces equal to their last reactions, × curve(t) after `at`.
      d.type = ConditionDesc::Type::release;
      d.release_from = c.string("from");
      auto it = radial_conditions.find(d.release_from);
      if (it == radial_conditions.end())
        c.fail("from", fmt::format("no radial_displacement condition named '{}' before this one", d.release_from));
      if (it->second != d.body) c.fail("from", fmt::format("'{}' holds body '{}', not '{}'", d.release_from, it->second, d.body));
      if (!released.insert(d.release_from).second) c.fail("from", fmt::format("'{}' is released twice", d.release_from));
      d.release_at = c.quantity("at", units::kTime);
      d.curve = c.string("curve");
      check_curve(c, d.curve);
      const double f = scene.curves.at(d.curve)(d.release_at);
      if (std::abs(f - 1.0) > 1e-12)
        c.fail("curve", fmt::format("the release curve '{}' must be 1 at the release time {} (it is {}): the forces start "
                                    "at the last reactions", d.curve, d.release_at, f));
      c.finish();
      scene.conditions.push_back(d);
      continue;
    }
    if (beam_type) {
      d.node = beams::read_beam_node_selector(c, "node");
      check_nodes(c, d.body, d.node);
      if (type == "clamp") {
        d.type = ConditionDesc::Type::clamp;
        // Hermite ends: position + rotation by default; the tangent carries the root shear strain.
        std::vector<std::string> fix{"position", "rotation"};
        if (c.has("fix")) {  // words: "position rotation tangent" (any of them)
          const std::string text = c.string("fix");
          fix.clear();
          std::string w;
          for (std::size_t i = 0; i <= text.size(); ++i) {
            if (i == text.size() || text[i] == ' ' || text[i] == ',') {
              if (w.empty()) continue;
              if (w != "position" && w != "rotation" && w != "tangent")
                c.fail("fix", fmt::format("'{}' is not one of position, rotation, tangent", w));
              fix.push_back(w);
              w.clear();
            } else {
              w += text[i];
            }
          }
          if (fix.empty()) c.fail("fix", "expected some of: position rotation tangent");
        }
        d.clamp_position = std::find(fix.begin(), fix.end(), "position") != fix.end();
        d.clamp_rotation = std::find(fix.begin(), fix.end(), "rotation") != fix.end();
        d.clamp_tangent = std::find(fix.begin(), fix.end(), "tangent") != fix.end();
        if (d.clamp_tangent && beam_body(d.body).body.interpolation != beams::BeamInterpolation::hermite3)
          c.fail("fix", "only Hermite (hermite3) beams have tangent DOFs");
      } else if (type == "direction") {
        d.type = ConditionDesc::Type::direction;
        if (c.has("direction") && c.node()["direction"].IsScalar()) {
          if (c.choice("direction", {"file"}) == "file") d.direction_from_file = true;
          if (d.node.kind != beams::BeamNodeSelector::Kind::fixations)
            c.fail("direction", "'file' takes the stent file's fixation directions; it needs node: fixations");
        } else {
          d.vector = vec3(c, "direction");
          if (!(d.vector.norm() > 0)) c.fail("direction", "must be a non-zero vector");
          d.vector.normalize();
        }
      } else if (type == "radial_displacement") {
        d.type = ConditionDesc::Type::radial_displacement;
        read_axis(c, d);
        d.value = c.quantity("value", units::kLength);
        d.curve = c.string("curve", "");
      } else if (type == "fix_cylindrical") {
        d.type = ConditionDesc::Type::fix_cylindrical;
        read_axis(c, d);
        const std::string text = c.string("components");  // words: radial circumferential axial
        std::string w;
        for (std::size_t i = 0; i <= text.size(); ++i) {
          if (i == text.size() || text[i] == ' ' || text[i] == ',') {
            if (w.empty()) continue;
            const int k = w == "radial" ? 0 : w == "circumferential" ? 1 : w == "axial" ? 2 : -1;
            if (k < 0) c.fail("components", fmt::format("'{}' is not one of radial, circumferential, axial", w));
            if (std::find(d.components.begin(), d.components.end(), k) == d.components.end()) d.components.push_back(k);
            w.clear();
          } else {
            w += text[i];
          }
        }
        if (d.components.empty()) c.fail("components", "expected some of: radial circumferential axial");
      } else {
        d.type = type == "point_force" ? ConditionDesc::Type::point_force : ConditionDesc::Type::point_moment;
        d.vector = vec3(c, "value");  // N (force) or N mm (moment), dead (fixed in space)
        d.curve = c.string("curve", "");
      }
      check_curve(c, d.curve);
      c.finish();
      scene.conditions.push_back(d);
      if (d.type == ConditionDesc::Type::radial_displacement) radial_conditions[d.name] = d.body;
      continue;
    }
    if (type == "pressure") {
      d.type = ConditionDesc::Type::pressure;
      d.where = read_selector(c, "surface");
      d.value = c.quantity("value", units::kPressure);
      d.curve = c.string("curve", "");
    } else if (type == "springs") {
      d.type = ConditionDesc::Type::springs;
      d.where = read_selector(c, "surface");
      d.value = c.quantity("stiffness", units::kStiffnessPerArea, std::nullopt, Range::positive());
    } else {
      d.type = ConditionDesc::Type::dirichlet;
      d.where = read_selector(c, "nodes");
      d.value = c.quantity("value", units::kLength, 0.0);
      d.curve = c.string("curve", "");
      if (auto r = c.optional_map("radial_only")) {
        d.radial_only = true;
        d.axis_origin = vec3(*r, "origin", Vec3::Zero());
        d.axis = vec3(*r, "axis", Vec3::UnitZ()).normalized();
        r->finish();
        if (d.value != 0.0) c.fail("value", "radial_only fixes the non-radial components to zero; value must be 0");
      } else {
        // "x", "xy", "x z", "xyz": the fixed global components.
        const std::string comps = c.string("components");
        for (char ch : comps) {
          if (ch == ' ' || ch == ',') continue;
          if (ch < 'x' || ch > 'z') c.fail("components", fmt::format("'{}' is not a list of x, y, z (e.g. 'xz')", comps));
          if (std::find(d.components.begin(), d.components.end(), ch - 'x') == d.components.end()) d.components.push_back(ch - 'x');
        }
        if (d.components.empty()) c.fail("components", "expected at least one of x, y, z (e.g. 'xyz')");
      }
    }
    check_curve(c, d.curve);
    c.finish();
    scene.conditions.push_back(d);
  }

  ConfigMap s = root.map("solver");
  ConfigMap time = s.map("time");
  scene.stepping.t_start = time.quantity("start", units::kTime, 0.0);
  scene.stepping.t_end = time.quantity("end", units::kTime, 1.0);
  if (scene.stepping.t_end <= scene.stepping.t_start) time.fail("end", "must be after start");
  scene.stepping.dt_initial = time.quantity("dt", units::kTime, 0.1, Range::positive());
  scene.stepping.dt_max = time.quantity("dt_max", units::kTime, scene.stepping.dt_initial, Range::positive());
  scene.stepping.dt_min = time.quantity("dt_min", units::kTime, 1e-6 * (scene.stepping.t_end - scene.stepping.t_start), Range::positive());
  scene.stepping.max_cuts = time.integer("max_cuts", 8, Range::between(0, 60));
  scene.stepping.max_consecutive_cuts = time.integer("max_consecutive_cuts", 12, Range::between(0, 200));
  scene.stepping.grow_factor = time.number("grow_factor", 1.5, Range{1.0, 10.0});
  scene.stepping.cut_factor = time.number("cut_factor", 0.5, Range{0.0, 1.0, false, false});
  scene.stepping.easy_iterations = time.integer("easy_iterations", 5, Range::between(1, 100));
  if (time.has("stops")) {
    const YAML::Node n = time.node()["stops"];
    scene.stepping.stops = time.numbers("stops", n.IsSequence() ? n.size() : 0);
  }
  time.finish();
  // A release happens at the end of a converged step: its time is a stop inside the run.
  for (const auto& c : scene.conditions) {
    if (c.type != ConditionDesc::Type::release) continue;
    if (!(c.release_at > scene.stepping.t_start && c.release_at < scene.stepping.t_end))
      throw InputError(fmt::format("{}: condition '{}': release time at = {} must lie inside solver.time ({}, {})", file.string(),
                                   c.name, c.release_at, scene.stepping.t_start, scene.stepping.t_end));
    scene.stepping.stops.push_back(c.release_at);
  }
  ConfigMap nw = s.map("newton");
  scene.newton.max_iterations = nw.integer("max_iterations", 20, Range::between(1, 1000));
  scene.newton.residual_tolerance = nw.number("residual_tolerance", 1e-8, Range::positive());
  scene.newton.residual_absolute = nw.number("residual_absolute", 1e-10, Range::non_negative());
  scene.newton.increment_tolerance = nw.number("increment_tolerance", 1e-8, Range::positive());
  scene.newton.line_search_steps = nw.integer("line_search_steps", 6, Range::between(0, 30));
  nw.finish();
  ConfigMap li = s.map("linear");
  scene.linear.type = li.choice("type", {"direct", "gmres_ilu", "gmres_amg", "eigen_lu"}, "direct");
  scene.linear.tolerance = li.number("tolerance", 1e-10, Range::positive());
  scene.linear.max_iterations = li.integer("max_iterations", 2000, Range::between(1, 1000000));
  scene.linear.krylov_size = li.integer("krylov_size", 200, Range::between(1, 10000));
  scene.linear.ilu_fill = li.integer("ilu_fill", 4, Range::between(0, 20));
  scene.linear.verbosity = li.integer("verbosity", 0, Range::between(0, 2));
  li.finish();
  s.finish();

  ConfigMap out = root.map("output");
  scene.output_every = out.integer("every", 1, Range::between(1, 1000000));
  scene.checkpoint_every = out.integer("checkpoint_every", 0, Range::between(0, 1000000));
  scene.load_factor_curve = out.string("load_factor_curve", scene.curves.empty() ? "" : scene.curves.begin()->first);
  if (!scene.load_factor_curve.empty() && !scene.curves.count(scene.load_factor_curve))
    out.fail("load_factor_curve", fmt::format("no load curve named '{}'", scene.load_factor_curve));
  out.finish();

  for (auto& q : root.map_list("qoi")) {
    QoiDesc d;
    d.name = q.string("name");
    const std::string type =
        q.choice("type", {"mean_radius", "max_displacement", "tip_position", "tip_rotation_angle", "ring_expansion"});
    d.type = type == "mean_radius"          ? QoiDesc::Type::mean_radius
             : type == "max_displacement"   ? QoiDesc::Type::max_displacement
             : type == "tip_position"       ? QoiDesc::Type::tip_position
             : type == "ring_expansion"     ? QoiDesc::Type::ring_expansion
                                            : QoiDesc::Type::tip_rotation_angle;
    d.body = q.string("body");
    check_body(q, d.body);
    const bool beam_qoi = d.type == QoiDesc::Type::tip_position || d.type == QoiDesc::Type::tip_rotation_angle ||
                          d.type == QoiDesc::Type::ring_expansion;
    check_kind(q, d.body, beam_qoi, type);
    if (d.type == QoiDesc::Type::ring_expansion) {
      for (const auto& other : scene.qois)
        if (other.type == QoiDesc::Type::ring_expansion) q.fail("type", "one ring_expansion QoI per scene (its summary keys have no prefix)");
      d.node = beams::read_beam_node_selector(q, "node");
      check_nodes(q, d.body, d.node);
      if (auto ax = q.optional_map("axis")) {
        d.axis_origin = vec3(*ax, "origin", Vec3::Zero());
        d.axis = vec3(*ax, "direction", Vec3::UnitZ()).normalized();
        ax->finish();
      }
      d.time = q.quantity("peak_time", units::kTime);  // D_max; D_end at the end
      if (!(d.time > scene.stepping.t_start && d.time <= scene.stepping.t_end))
        q.fail("peak_time", "must lie inside solver.time");
      scene.stepping.stops.push_back(d.time);
      q.finish();
      scene.qois.push_back(d);
      continue;
    }
    if (beam_qoi) {
      d.node = beams::read_beam_node_selector(q, "node");
      if (d.node.kind == beams::BeamNodeSelector::Kind::fixations) q.fail("node", "a tip QoI needs one node (first, last or a point)");
      check_nodes(q, d.body, d.node);
      if (beams::select_beam_nodes(beam_body(d.body), d.node).size() != 1) q.fail("node", "selects more than one node");
    } else {
      d.where = read_selector(q, "nodes");
    }
    if (d.type == QoiDesc::Type::mean_radius) {
      ConfigMap ax = q.map("axis");
      d.axis_origin = vec3(ax, "origin", Vec3::Zero());
      d.axis = vec3(ax, "direction", Vec3::UnitZ()).normalized();
      ax.finish();
    }
    d.time = q.quantity("time", units::kTime, scene.stepping.t_end);
    // the QoI is taken at an output step: make its time a stop
    scene.stepping.stops.push_back(d.time);
    q.finish();
    scene.qois.push_back(d);
  }
  root.finish();
  return scene;
}

}  // namespace stentsim::solver
