#include "solver/io/selection.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <set>

#include "common/error.hpp"

namespace stentsim::solver {
namespace {

Vec3 vec(ConfigMap& m, const std::string& key) {
  const auto v = m.numbers(key, 3);
  return {v[0], v[1], v[2]};
}

double mesh_size(const MeshData& mesh) {
  if (mesh.points.empty()) return 1.0;
  Vec3 lo = mesh.points[0], hi = lo;
  for (const auto& p : mesh.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return std::max((hi - lo).norm(), 1e-12);
}

std::vector<char> node_mask(const MeshData& mesh, const Selector& s) {
  std::vector<char> mask(mesh.points.size(), 0);
  const double tol = s.tolerance >= 0 ? s.tolerance : 1e-6 * mesh_size(mesh);
  const DataArray* arr = nullptr;
  if (s.kind == Selector::Kind::point_array) {
    auto it = mesh.point_data.find(s.array);
    if (it == mesh.point_data.end()) throw InputError(fmt::format("selection: the mesh has no point array '{}'", s.array));
    arr = &it->second;
  }
  for (std::size_t i = 0; i < mesh.points.size(); ++i) {
    const Vec3& p = mesh.points[i];
    bool in = false;
    switch (s.kind) {
      case Selector::Kind::all: in = true; break;
      case Selector::Kind::plane: in = std::abs((p - s.a).dot(s.b.normalized())) <= tol; break;
      case Selector::Kind::cylinder: {
        const Vec3 ax = s.b.normalized(), d = p - s.a;
        in = std::abs((d - d.dot(ax) * ax).norm() - s.radius) <= tol && (!s.axial || std::abs(d.dot(ax) - *s.axial) <= tol);
        break;
      }
      case Selector::Kind::box: in = (p.array() >= s.a.array() - tol).all() && (p.array() <= s.b.array() + tol).all(); break;
      case Selector::Kind::point_array: in = std::abs(arr->at(i) - s.value) < 1e-9; break;
      case Selector::Kind::cell_array: in = false; break;
    }
    mask[i] = in ? 1 : 0;
  }
  return mask;
}

}  // namespace

std::string Selector::describe() const {
  switch (kind) {
    case Kind::all: return "all";
    case Kind::plane: return fmt::format("plane through ({:g},{:g},{:g}) normal ({:g},{:g},{:g})", a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
    case Kind::cylinder:
      return fmt::format("cylinder radius {:g} about ({:g},{:g},{:g})+s({:g},{:g},{:g}){}", radius, a.x(), a.y(), a.z(), b.x(), b.y(), b.z(),
                         axial ? fmt::format(" at {:g} along it", *axial) : std::string());
    case Kind::box: return "box";
    case Kind::point_array: return fmt::format("point array {} = {:g}", array, value);
    case Kind::cell_array: return fmt::format("cell array {} = {:g}", array, value);
  }
  return "?";
}

Selector read_selector(ConfigMap& cfg, const std::string& key) {
  ConfigMap m = cfg.map(key);
  Selector s;
  int kinds = 0;
  if (m.has("all")) {
    ++kinds;
    if (!m.boolean("all")) m.fail("all", "write 'all: true' or choose another selection");
  }
  if (auto p = m.optional_map("plane")) {
    ++kinds;
    s.kind = Selector::Kind::plane;
    s.a = vec(*p, "point");
    s.b = vec(*p, "normal");
    if (s.b.norm() == 0) p->fail("normal", "must not be zero");
    s.tolerance = p->quantity("tolerance", units::kLength, -1.0);
    p->finish();
  }
  if (auto p = m.optional_map("cylinder")) {
    ++kinds;
    s.kind = Selector::Kind::cylinder;
    s.a = vec(*p, "origin");
    s.b = vec(*p, "axis");
    if (s.b.norm() == 0) p->fail("axis", "must not be zero");
    s.radius = p->quantity("radius", units::kLength, std::nullopt, Range::positive());
    if (p->has("at")) s.axial = p->quantity("at", units::kLength);
    s.tolerance = p->quantity("tolerance", units::kLength, -1.0);
    p->finish();
  }
  if (auto p = m.optional_map("box")) {
    ++kinds;
    s.kind = Selector::Kind::box;
    s.a = vec(*p, "min");
    s.b = vec(*p, "max");
    s.tolerance = p->quantity("tolerance", units::kLength, -1.0);
    p->finish();
  }
  for (const char* k : {"point_array", "cell_array"}) {
    if (auto p = m.optional_map(k)) {
      ++kinds;
      s.kind = std::string(k) == "point_array" ? Selector::Kind::point_array : Selector::Kind::cell_array;
      s.array = p->string("name");
      s.value = p->number("value");
      p->finish();
    }
  }
  if (kinds != 1)
    cfg.fail(key, "expected exactly one of: all, plane, cylinder, box, point_array, cell_array");
  m.finish();
  return s;
}

std::vector<std::size_t> select_nodes(const MeshData& mesh, const Selector& s) {
  if (s.kind == Selector::Kind::cell_array) {
    std::set<std::size_t> nodes;
    auto it = mesh.cell_data.find(s.array);
    if (it == mesh.cell_data.end()) throw InputError(fmt::format("selection: the mesh has no cell array '{}'", s.array));
    for (std::size_t c = 0; c < mesh.num_cells(); ++c)
      if (std::abs(it->second.at(c) - s.value) < 1e-9)
        for (auto n : mesh.cell(c)) nodes.insert(static_cast<std::size_t>(n));
    return {nodes.begin(), nodes.end()};
  }
  const auto mask = node_mask(mesh, s);
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < mask.size(); ++i)
    if (mask[i]) out.push_back(i);
  return out;
}

std::vector<fem::Face> select_faces(const MeshData& mesh, const std::vector<fem::Face>& boundary, const Selector& s) {
  std::vector<fem::Face> out;
  if (s.kind == Selector::Kind::cell_array) {
    auto it = mesh.cell_data.find(s.array);
    if (it == mesh.cell_data.end()) throw InputError(fmt::format("selection: the mesh has no cell array '{}'", s.array));
    std::set<std::vector<std::int64_t>> tagged;
    for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
      const auto t = mesh.cell_types[c];
      if (t != CellType::triangle && t != CellType::quad && t != CellType::quadratic_triangle) continue;
      if (std::abs(it->second.at(c) - s.value) > 1e-9) continue;
      auto conn = mesh.cell(c);
      conn.resize(t == CellType::quad ? 4 : 3);
      std::sort(conn.begin(), conn.end());
      tagged.insert(conn);
    }
    for (const auto& f : boundary) {
      std::vector<std::int64_t> key(f.nodes.begin(), f.nodes.begin() + (f.type == CellType::quad ? 4 : 3));
      std::sort(key.begin(), key.end());
      if (tagged.count(key)) out.push_back(f);
    }
    return out;
  }
  const auto mask = node_mask(mesh, s);
  for (const auto& f : boundary) {
    bool all = true;
    for (int i = 0; i < f.count && all; ++i) all = mask[static_cast<std::size_t>(f.nodes[static_cast<std::size_t>(i)])] != 0;
    if (all) out.push_back(f);
  }
  return out;
}

}  // namespace stentsim::solver
