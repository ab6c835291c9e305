// CGAL adapter: Delaunay tetrahedralization of the surface vertices and the
// interior part of its dual Voronoi diagram.
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <Eigen/Geometry>
#include <cmath>

#include "segmentation_io/medial_axis.hpp"

namespace stentsim::segmentation {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, K>;
using Cb = CGAL::Triangulation_cell_base_with_info_3<int, K, CGAL::Delaunay_triangulation_cell_base_3<K>>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;

std::vector<Eigen::Vector3d> vertex_normals(const TriSurface& s) {
  std::vector<Eigen::Vector3d> n(s.points.size(), Eigen::Vector3d::Zero());
  for (const auto& t : s.triangles) {
    Eigen::Vector3d a = (s.points[t[1]] - s.points[t[0]]).cross(s.points[t[2]] - s.points[t[0]]);
    for (int v : t) n[v] += a;
  }
  for (auto& v : n)
    if (v.norm() > 0) v.normalize();
  return n;
}

MedialGraph interior_voronoi_graph(const TriSurface& s) {
  const auto normals = vertex_normals(s);
  std::vector<std::pair<K::Point_3, int>> pts;
  pts.reserve(s.points.size());
  std::vector<bool> used(s.points.size(), false);
  for (const auto& t : s.triangles)
    for (int v : t) used[v] = true;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (used[i]) pts.emplace_back(K::Point_3(s.points[i].x(), s.points[i].y(), s.points[i].z()), int(i));
  Delaunay dt(pts.begin(), pts.end());

  const double max_radius = bounding_box_diagonal(s);
  MedialGraph g;
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
    c->info() = -1;
    Eigen::Vector3d p[4];
    int id[4];
    for (int k = 0; k < 4; ++k) {
      const auto& q = c->vertex(k)->point();
      p[k] = {q.x(), q.y(), q.z()};
      id[k] = c->vertex(k)->info();
    }
    // Circumcentre by the closed form (robust enough here: flat tetrahedra give
    // non-finite or huge centres, which are dropped below).
    Eigen::Vector3d a = p[1] - p[0], b = p[2] - p[0], d = p[3] - p[0];
    double det = 2 * a.dot(b.cross(d));
    if (std::abs(det) < 1e-300) continue;
    Eigen::Vector3d x = (a.squaredNorm() * b.cross(d) + b.squaredNorm() * d.cross(a) + d.squaredNorm() * a.cross(b)) / det;
    double r = x.norm();
    if (!std::isfinite(r) || r > max_radius) continue;
    Eigen::Vector3d centre = p[0] + x;
    bool inner = true;
    for (int k = 0; k < 4 && inner; ++k) inner = (centre - p[k]).dot(normals[id[k]]) < 0;
    if (!inner) continue;
    c->info() = int(g.centers.size());
    g.centers.push_back(centre);
    g.radius.push_back(r);
  }
  g.neighbours.resize(g.centers.size());
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
    if (c->info() < 0) continue;
    for (int k = 0; k < 4; ++k) {
      auto n = c->neighbor(k);
      if (dt.is_infinite(n) || n->info() < 0) continue;
      g.neighbours[c->info()].push_back(n->info());
    }
  }
  return g;
}

}  // namespace stentsim::segmentation
