#include "segmentation_io/triangle_surface.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <unordered_map>

#include "common/error.hpp"

namespace stentsim::segmentation {

TriSurface surface_from_mesh(const MeshData& mesh, const std::string& what) {
  TriSurface s;
  s.points = mesh.points;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    auto nodes = mesh.cell(c);
    switch (mesh.cell_types[c]) {
      case CellType::triangle:
        s.triangles.push_back({int(nodes[0]), int(nodes[1]), int(nodes[2])});
        break;
      case CellType::quad:
        s.triangles.push_back({int(nodes[0]), int(nodes[1]), int(nodes[2])});
        s.triangles.push_back({int(nodes[0]), int(nodes[2]), int(nodes[3])});
        break;
      case CellType::vertex:
      case CellType::line:
      case CellType::polyline:
        break;
      default:
        throw InputError(fmt::format("{}: cell {} has VTK type {}; a surface of triangles (or quads) was expected",
                                     what, c, int(mesh.cell_types[c])));
    }
  }
  if (s.triangles.empty()) throw InputError(fmt::format("{}: the surface has no triangles", what));
  for (const auto& t : s.triangles)
    for (int v : t)
      if (v < 0 || v >= int(s.points.size()))
        throw InputError(fmt::format("{}: a triangle refers to point {} but there are {} points", what, v,
                                     s.points.size()));
  return s;
}

MeshData mesh_from_surface(const TriSurface& s) {
  MeshData m;
  m.points = s.points;
  m.cell_types.reserve(s.triangles.size());
  m.connectivity.reserve(3 * s.triangles.size());
  m.cell_offsets.reserve(s.triangles.size() + 1);
  for (const auto& t : s.triangles) m.add_cell(CellType::triangle, {t[0], t[1], t[2]});
  return m;
}

std::vector<BoundaryLoop> boundary_loops(const TriSurface& s) {
  // Directed half-edges; a boundary edge is one whose twin is missing.
  std::map<std::pair<int, int>, int> count;
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) {
      int a = t[k], b = t[(k + 1) % 3];
      ++count[{std::min(a, b), std::max(a, b)}];
    }
  std::unordered_multimap<int, int> next;  // boundary half-edge a->b as oriented in its triangle
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) {
      int a = t[k], b = t[(k + 1) % 3];
      if (count[{std::min(a, b), std::max(a, b)}] == 1) next.emplace(a, b);
    }
  std::vector<BoundaryLoop> loops;
  while (!next.empty()) {
    auto it = next.begin();
    int start = it->first;
    BoundaryLoop loop;
    int cur = start;
    for (;;) {
      auto e = next.find(cur);
      if (e == next.end()) break;  // open chain (inconsistent orientation): stop here
      int nb = e->second;
      next.erase(e);
      loop.vertices.push_back(cur);
      cur = nb;
      if (cur == start) break;
    }
    if (loop.vertices.size() < 2) continue;
    double len = 0;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < loop.vertices.size(); ++i) {
      const auto& a = s.points[loop.vertices[i]];
      const auto& b = s.points[loop.vertices[(i + 1) % loop.vertices.size()]];
      double l = (b - a).norm();
      len += l;
      c += 0.5 * l * (a + b);
    }
    loop.perimeter = len;
    loop.centroid = len > 0 ? Eigen::Vector3d(c / len) : s.points[loop.vertices[0]];
    double r = 0;
    for (int v : loop.vertices) r += (s.points[v] - loop.centroid).norm();
    loop.mean_radius = r / double(loop.vertices.size());
    loops.push_back(std::move(loop));
  }
  std::sort(loops.begin(), loops.end(), [](const auto& a, const auto& b) { return a.perimeter > b.perimeter; });
  return loops;
}

TriSurface capped(const TriSurface& s, const std::vector<BoundaryLoop>& loops) {
  TriSurface out = s;
  for (const auto& loop : loops) {
    int c = int(out.points.size());
    out.points.push_back(loop.centroid);
    // The loop runs along its triangles' edges a->b; the cap uses b->a so that
    // the cap's orientation continues the surface's.
    for (std::size_t i = 0; i < loop.vertices.size(); ++i) {
      int a = loop.vertices[i], b = loop.vertices[(i + 1) % loop.vertices.size()];
      out.triangles.push_back({b, a, c});
    }
  }
  return out;
}

double signed_volume(const TriSurface& s) {
  double v = 0;
  for (const auto& t : s.triangles)
    v += s.points[t[0]].dot(s.points[t[1]].cross(s.points[t[2]]));
  return v / 6.0;
}

double surface_area(const TriSurface& s) {
  double a = 0;
  for (const auto& t : s.triangles)
    a += 0.5 * (s.points[t[1]] - s.points[t[0]]).cross(s.points[t[2]] - s.points[t[0]]).norm();
  return a;
}

double bounding_box_diagonal(const TriSurface& s) {
  if (s.points.empty()) return 0;
  Eigen::Vector3d lo = s.points[0], hi = s.points[0];
  for (const auto& p : s.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

}  // namespace stentsim::segmentation
