// CGAL adapter: self-intersection test (Polygon Mesh Processing).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <iterator>

#include "segmentation_io/surface_input.hpp"

namespace stentsim::segmentation {

std::vector<std::pair<int, int>> self_intersections(const TriSurface& s, std::size_t limit) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  namespace PMP = CGAL::Polygon_mesh_processing;
  Mesh mesh;
  std::vector<Mesh::Vertex_index> v;
  for (const auto& p : s.points) v.push_back(mesh.add_vertex(K::Point_3(p.x(), p.y(), p.z())));
  std::vector<int> face_to_triangle;
  for (std::size_t i = 0; i < s.triangles.size(); ++i) {
    const auto& t = s.triangles[i];
    if (mesh.add_face(v[t[0]], v[t[1]], v[t[2]]) != Mesh::null_face()) face_to_triangle.push_back(int(i));
  }
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  PMP::self_intersections(faces(mesh), mesh, std::back_inserter(pairs));
  std::vector<std::pair<int, int>> out;
  for (const auto& [a, b] : pairs) {
    if (out.size() >= limit) break;
    out.emplace_back(face_to_triangle[std::size_t(a)], face_to_triangle[std::size_t(b)]);
  }
  return out;
}

}  // namespace stentsim::segmentation
