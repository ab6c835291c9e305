// CGAL adapter: the self-intersection test of common/self_intersection.hpp.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <iterator>

#include "common/self_intersection.hpp"

namespace stentsim {

std::vector<std::pair<int, int>> self_intersecting_triangles(const std::vector<Eigen::Vector3d>& points,
                                                             const std::vector<std::array<int, 3>>& triangles,
                                                             std::size_t limit) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  namespace PMP = CGAL::Polygon_mesh_processing;
  Mesh mesh;
  std::vector<Mesh::Vertex_index> v;
  v.reserve(points.size());
  for (const auto& p : points) v.push_back(mesh.add_vertex(K::Point_3(p.x(), p.y(), p.z())));
  std::vector<int> face_to_triangle;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    if (mesh.add_face(v[std::size_t(t[0])], v[std::size_t(t[1])], v[std::size_t(t[2])]) != Mesh::null_face())
      face_to_triangle.push_back(int(i));
  }
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  PMP::self_intersections(faces(mesh), mesh, std::back_inserter(pairs));
  std::vector<std::pair<int, int>> out;
  for (const auto& [a, b] : pairs) {
    if (out.size() >= limit) break;
    const int i = face_to_triangle[std::size_t(a)], j = face_to_triangle[std::size_t(b)];
    out.emplace_back(std::min(i, j), std::max(i, j));
  }
  return out;
}

}  // namespace stentsim
