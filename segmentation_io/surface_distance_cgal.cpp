// CGAL adapter: AABB-tree distance queries and inside/outside tests.
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <fmt/format.h>

#include "common/error.hpp"
#include "segmentation_io/surface_distance.hpp"

namespace stentsim::segmentation {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangles = std::vector<K::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

struct SurfaceDistance::Impl {
  Triangles triangles;
  Tree tree;
};

namespace {
K::Point_3 to_cgal(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }
}  // namespace

SurfaceDistance::SurfaceDistance(const TriSurface& s) : impl_(std::make_unique<Impl>()) {
  impl_->triangles.reserve(s.triangles.size());
  for (const auto& t : s.triangles) {
    K::Triangle_3 tri(to_cgal(s.points[t[0]]), to_cgal(s.points[t[1]]), to_cgal(s.points[t[2]]));
    if (!tri.is_degenerate()) impl_->triangles.push_back(tri);
  }
  if (impl_->triangles.empty()) throw ComputeError("distance queries: the surface has no non-degenerate triangle");
  impl_->tree.insert(impl_->triangles.cbegin(), impl_->triangles.cend());
  impl_->tree.build();
  impl_->tree.accelerate_distance_queries();
}

SurfaceDistance::~SurfaceDistance() = default;

double SurfaceDistance::distance(const Eigen::Vector3d& p) const {
  return std::sqrt(impl_->tree.squared_distance(to_cgal(p)));
}

Eigen::Vector3d SurfaceDistance::closest_point(const Eigen::Vector3d& p) const {
  auto q = impl_->tree.closest_point(to_cgal(p));
  return {q.x(), q.y(), q.z()};
}

std::vector<bool> inside_closed_surface(const TriSurface& s, const std::vector<Eigen::Vector3d>& points) {
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  Mesh mesh;
  std::vector<Mesh::Vertex_index> v;
  v.reserve(s.points.size());
  for (const auto& p : s.points) v.push_back(mesh.add_vertex(to_cgal(p)));
  for (const auto& t : s.triangles)
    if (mesh.add_face(v[t[0]], v[t[1]], v[t[2]]) == Mesh::null_face())
      throw ComputeError("inside test: the surface is not a consistently oriented 2-manifold");
  for (auto h : mesh.halfedges())
    if (mesh.is_border(h)) throw ComputeError("inside test: the surface is not closed");
  CGAL::Side_of_triangle_mesh<Mesh, K> side(mesh);
  std::vector<bool> inside(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) inside[i] = side(to_cgal(points[i])) == CGAL::ON_BOUNDED_SIDE;
  return inside;
}

}  // namespace stentsim::segmentation
