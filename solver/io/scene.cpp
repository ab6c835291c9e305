#include "solver/io/scene.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <sstream>

#include "common/error.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/io/scene_kinds.hpp"
#include "solver/linalg/linear_solver_config.hpp"
#include "solver/materials/presets.hpp"

namespace stentsim::solver {
namespace {

Vec3 vec3(ConfigMap& m, const std::string& key, std::optional<Vec3> def = std::nullopt) {
  std::optional<std::vector<double>> d;
  if (def) d = std::vector<double>{def->x(), def->y(), def->z()};
  const auto v = m.numbers(key, 3, d);
  return {v[0], v[1], v[2]};
}

// A generated mesh's element count before anything is allocated: refused above
// kMaxGeneratedElements (of the requested kind: a hex8 splits into 6 tets), so a typo
// of a few zeros is an error naming the key, never minutes of allocation or bad_alloc.
constexpr double kMaxGeneratedElements = 5e6;
void check_generated_count(ConfigMap& g, const std::string& key, const std::string& product, double hex8, const std::string& element) {
  const double n = element == "hex8" ? hex8 : 6 * hex8;
  if (n > kMaxGeneratedElements)
    g.fail(key, fmt::format("{} gives {:.3g} {} elements, more than the {:.0e} a generated mesh may have; read a larger "
                            "model from a .vtu (file:)",
                            product, n, element, kMaxGeneratedElements));
}

MeshData read_mesh(ConfigMap& m, std::string& source) {
  const bool has_file = m.has("file"), has_gen = m.has("generate");
  if (has_file == has_gen) m.fail("", "give exactly one of 'file' (a .vtu) or 'generate'");
  if (has_file) {
    const auto path = m.path("file");
    source = path.string();
    if (path.extension() != ".vtu") m.fail("file", "expected a .vtu file");
    if (!std::filesystem::is_regular_file(path)) m.fail("file", fmt::format("no such file: {}", path.string()));
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
    // 360 deg closes the ring: the seam's nodes are shared.
    if (angle == 360.0 && nt < 3) g.fail("circumferential", "a closed ring needs at least 3 elements around");
    check_generated_count(g, "axial", "radial x circumferential x axial", double(nr) * nt * nz, element);
    mesh = ring_sector_hex8(ri, ro, angle * std::numbers::pi / 180.0, height, nr, nt, nz);
    source = fmt::format("generated ring sector {}x{}x{} {}", nr, nt, nz, element);
  } else {
    const auto size = g.numbers("size", 3);
    const auto cells = g.numbers("cells", 3);
    for (double v : size)
      if (!(v > 0 && std::isfinite(v))) g.fail("size", fmt::format("expected three positive lengths (mm), got {:g}", v));
    for (double v : cells)
      if (!(v >= 1 && v <= 1e5 && v == std::floor(v)))
        g.fail("cells", fmt::format("expected three whole numbers of cells from 1 to 100000, got {:g}", v));
    check_generated_count(g, "cells", "the product of cells", cells[0] * cells[1] * cells[2], element);
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
  // svMultiPhysics's HGO: decoupled neo-Hooke matrix, and the fibers on Ibar4.
  if (auto dh = m.optional_map("decoupled_hgo")) {
    if (mat.matrix)
      m.fail("decoupled_hgo", "replaces the coupled neo-Hooke matrix: drop 'neo_hooke' (and 'preset') from this material");
    const double e = dh->quantity("E", units::kPressure, std::nullopt, Range::positive());
    const double nu = dh->number("nu", std::nullopt, Range{-1.0, 0.5, false, false});
    mat.decoupled_matrix = DecoupledNeoHooke::from_young_poisson(e, nu);
    dh->finish();
  }
  if (m.has("fibers")) {
    mat.fibers.clear();
    for (auto& f : m.map_list("fibers")) {
      FiberFamilySpec s;
      s.law.k1 = f.quantity("k1", units::kPressure, std::nullopt, Range::non_negative());
      s.law.k2 = f.number("k2", std::nullopt, Range::non_negative());
      s.law.tension_only = f.boolean("tension_only", false);
      s.law.multiplicity = f.number("count", 1.0, Range::positive());
      s.law.isochoric = mat.decoupled_matrix.has_value();
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
  if (!mat.matrix && !mat.decoupled_matrix && mat.fibers.empty())
    m.fail("", "a material needs a 'preset', 'neo_hooke', 'decoupled_hgo' or 'fibers'");
  if (static_cast<int>(mat.fibers.size()) > kMaxFiberFamilies)
    m.fail("fibers", fmt::format("at most {} fiber families", kMaxFiberFamilies));
  return mat;
}

}  // namespace

const BodyDesc* SceneDesc::body(const std::string& name) const {
  for (const auto& b : bodies)
    if (b.name == name) return &b;
  return nullptr;
}

const BodyDesc& SceneReader::body(ConfigMap& c, const std::string& key, std::optional<bool> beam, const std::string& type) const {
  const std::string name = c.string(key);
  const BodyDesc* b = scene.body(name);
  if (!b) {
    std::vector<std::string> names;
    for (const auto& x : scene.bodies) names.push_back(x.name);
    const std::string near = closest_name(names, name);
    c.fail(key, fmt::format("no body named '{}'{}", name, near.empty() ? std::string() : fmt::format(" (did you mean '{}'?)", near)));
  }
  if (beam && b->beam.has_value() != *beam)
    c.fail(key, fmt::format("'{}' applies to {} bodies; '{}' is a {} body", type, *beam ? "beam" : "solid", name,
                            b->beam ? "beam" : "solid"));
  return *b;
}

std::string SceneReader::curve(ConfigMap& c, const std::string& key, bool required) const {
  const std::string name = required ? c.string(key) : c.string(key, "");
  if (!name.empty() && !scene.curves.count(name)) c.fail(key, fmt::format("no load curve named '{}' in load_curves", name));
  return name;
}

beams::BeamNodeSelector SceneReader::beam_nodes(ConfigMap& c, const std::string& key, const BodyDesc& body) const {
  const beams::BeamNodeSelector sel = beams::read_beam_node_selector(c, key);
  std::vector<int> nodes;
  try {
    nodes = beams::select_beam_nodes(*body.beam, sel);
  } catch (const InputError& e) {
    c.fail(key, e.what());
  }
  if (nodes.empty()) c.fail(key, fmt::format("selects no end node of beam body '{}' ({})", body.name, sel.describe()));
  return sel;
}

Vec3 SceneReader::vec3(ConfigMap& m, const std::string& key, std::optional<Vec3> def) { return solver::vec3(m, key, def); }

void SceneReader::axis(ConfigMap& c, const std::string& key, Vec3& origin, Vec3& direction) {
  origin = Vec3::Zero(), direction = Vec3::UnitZ();
  if (auto ax = c.optional_map(key)) {
    origin = solver::vec3(*ax, "origin", Vec3::Zero());
    direction = solver::vec3(*ax, "direction", Vec3::UnitZ());
    if (!(direction.norm() > 0)) ax->fail("direction", "must be a non-zero vector");
    direction.normalize();
    ax->finish();
  }
}

namespace {
SceneDesc read_scene_root(ConfigMap root, const std::filesystem::path& file);
}

SceneDesc read_scene(const std::filesystem::path& file) { return read_scene_root(ConfigMap::load(file), file); }

SceneDesc read_scene(const std::string& text, const std::filesystem::path& file) {
  return read_scene_root(ConfigMap::from_string(text, file), file);
}

namespace {

// Every value under a key `file` (a mesh, a beam, a fiber-frame file), resolved as ConfigMap::path does.
void collect_files(const YAML::Node& n, const std::filesystem::path& dir, std::vector<std::filesystem::path>& out) {
  if (n.IsMap()) {
    for (const auto& kv : n) {
      if (kv.first.Scalar() == "file" && kv.second.IsScalar()) {
        std::filesystem::path p = kv.second.Scalar();
        if (p.is_relative()) p = dir / p;
        out.push_back(std::filesystem::absolute(p).lexically_normal());
      } else {
        collect_files(kv.second, dir, out);
      }
    }
  } else if (n.IsSequence()) {
    for (const auto& e : n) collect_files(e, dir, out);
  }
}

SceneDesc read_scene_root(ConfigMap root, const std::filesystem::path& file) {
  SceneDesc scene;
  scene.file = file;
  scene.description = root.string("description", "");

  std::set<std::string> names;
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
        if (!std::filesystem::is_regular_file(body.frames.file))
          f->fail("file", fmt::format("no such file: {}", body.frames.file.string()));
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
  SceneReader reader(scene);
  auto names_of = [](const auto& kinds) {
    std::vector<std::string> n;
    for (const auto& k : kinds) n.push_back(k.type);
    return n;
  };
  // One entry of a kind family: type, then name (unique; default <type>_<index>), then the kind's keys.
  auto read_entry = [&](ConfigMap& c, const auto& kinds, const auto& existing, int index, bool name_required) {
    const std::string type = c.choice("type", names_of(kinds));
    const std::string name = name_required ? c.string("name") : c.string("name", fmt::format("{}_{}", type, index));
    for (const auto& other : existing)
      if (other->name == name) c.fail("name", fmt::format("the name '{}' is used twice", name));
    for (const auto& k : kinds)
      if (k.type == type) {
        auto spec = k.read(c, reader);
        spec->name = name;
        c.finish();
        return spec;
      }
    throw std::logic_error("scene kind lookup");
  };
  int index = 0;
  for (auto& c : root.map_list("conditions")) scene.conditions.push_back(read_entry(c, condition_kinds(), scene.conditions, index++, false));

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
  for (const auto& c : scene.conditions) c->add_stops(scene, scene.stepping.stops);
  // Load turns: the times inside the run where a load curve changes slope (held
  // constant past its last point). Steps end on them and start small after them.
  for (const auto& [name, curve] : scene.curves) {
    const auto& pts = curve.points();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double t = pts[i].first;
      if (!(t > scene.stepping.t_start && t < scene.stepping.t_end)) continue;
      const double before = i > 0 ? (pts[i].second - pts[i - 1].second) / (t - pts[i - 1].first) : 0.0;
      const double after = i + 1 < pts.size() ? (pts[i + 1].second - pts[i].second) / (pts[i + 1].first - t) : 0.0;
      if (std::abs(after - before) > 1e-12 * std::max(std::abs(after), std::abs(before))) {
        scene.stepping.load_turns.push_back(t);
        scene.stepping.stops.push_back(t);
      }
    }
  }
  ConfigMap nw = s.map("newton");
  scene.newton.max_iterations = nw.integer("max_iterations", 20, Range::between(1, 1000));
  scene.newton.residual_tolerance = nw.number("residual_tolerance", 1e-8, Range::positive());
  scene.newton.residual_absolute = nw.number("residual_absolute", 1e-10, Range::non_negative());
  scene.newton.increment_tolerance = nw.number("increment_tolerance", 1e-8, Range::positive());
  scene.newton.floor_tolerance = nw.number("floor_tolerance", 1e-6, Range::non_negative());
  scene.newton.floor_iterations = nw.integer("floor_iterations", 2, Range::between(1, 100));
  scene.newton.floor_reduction = nw.number("floor_reduction", 0.9, Range{0.0, 1.0, false, true});
  scene.newton.line_search_steps = nw.integer("line_search_steps", 6, Range::between(0, 30));
  scene.newton.predictor = nw.choice("predictor", {"extrapolate", "none"}, "extrapolate") == "extrapolate";
  scene.newton.inexact = nw.choice("forcing", {"eisenstat_walker", "none"}, "eisenstat_walker") == "eisenstat_walker";
  nw.finish();
  ConfigMap li = s.map("linear");
  scene.linear.type = read_linear_solver(li, "type", LinearSolverType::direct);
  scene.linear.tolerance = li.number("tolerance", 1e-10, Range::positive());
  scene.linear.max_iterations = li.integer("max_iterations", 2000, Range::between(1, 1000000));
  scene.linear.krylov_size = li.integer("krylov_size", 200, Range::between(1, 10000));
  scene.linear.ilu_fill = li.integer("ilu_fill", 4, Range::between(0, 20));
  scene.linear.verbosity = li.integer("verbosity", 0, Range::between(0, 2));
  if (li.has("amg_parameters")) {
    if (scene.linear.type != LinearSolverType::gmres_amg && scene.linear.type != LinearSolverType::gmres_amg_block)
      li.fail("amg_parameters", "applies to types gmres_amg and gmres_amg_block only");
    const auto xml = li.path("amg_parameters");
    if (!std::filesystem::is_regular_file(xml)) li.fail("amg_parameters", fmt::format("no such file: {}", xml.string()));
    scene.linear.amg_parameters = xml.string();
  }
  if (li.has("preconditioner_update")) {
    if (scene.linear.type == LinearSolverType::direct || scene.linear.type == LinearSolverType::eigen_lu)
      li.fail("preconditioner_update", "applies to the Krylov types (gmres_ilu, gmres_amg, gmres_amg_block, gmres_lu) only");
    scene.linear.lag_preconditioner = li.choice("preconditioner_update", {"lagged", "every_solve"}, "lagged") == "lagged";
  }
  li.finish();
  s.finish();

  ConfigMap out = root.map("output");
  scene.output_every = out.integer("every", 1, Range::between(1, 1000000));
  scene.checkpoint_every = out.integer("checkpoint_every", 0, Range::between(0, 1000000));
  scene.load_factor_curve = out.string("load_factor_curve", scene.curves.empty() ? "" : scene.curves.begin()->first);
  if (!scene.load_factor_curve.empty() && !scene.curves.count(scene.load_factor_curve))
    out.fail("load_factor_curve", fmt::format("no load curve named '{}'", scene.load_factor_curve));
  out.finish();

  // Contact pairs and QoIs after solver.time: their report times must lie inside it and become stops.
  index = 0;
  if (root.has("contact"))
    for (auto& c : root.map_list("contact")) scene.contacts.push_back(read_entry(c, contact_kinds(), scene.contacts, index++, false));
  index = 0;
  for (auto& q : root.map_list("qoi")) scene.qois.push_back(read_entry(q, qoi_kinds(), scene.qois, index++, true));
  root.finish();
  const YAML::Node& top = root.node();
  for (const char* section : {"bodies", "conditions", "contact"})
    scene.state_sections[section] = top[section].IsDefined() ? canonical_yaml(top[section]) : "";
  collect_files(top["bodies"], file.parent_path(), scene.state_files);
  return scene;
}

}  // namespace

}  // namespace stentsim::solver
