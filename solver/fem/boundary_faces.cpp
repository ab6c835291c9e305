#include "solver/fem/boundary_faces.hpp"

#include <algorithm>
#include <map>

#include <Eigen/Geometry>

namespace stentsim::solver::fem {
namespace {

// Local faces with outward orientation for VTK node order.
const std::vector<std::vector<int>> kHexFaces{{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                              {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
const std::vector<std::vector<int>> kTetFaces{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
const std::vector<std::vector<int>> kTet10Faces{{0, 2, 1, 6, 5, 4}, {0, 1, 3, 4, 8, 7}, {1, 2, 3, 5, 9, 8}, {0, 3, 2, 7, 9, 6}};

Eigen::Vector3d face_normal(const MeshData& m, const Face& f) {
  // Newell's normal of the corner polygon (corners come first in VTK order).
  const int corners = f.type == CellType::quad ? 4 : 3;
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (int i = 0; i < corners; ++i)
    n += m.points[static_cast<std::size_t>(f.nodes[i])].cross(m.points[static_cast<std::size_t>(f.nodes[(i + 1) % corners])]);
  return n;
}

void flip(Face& f) {
  if (f.type == CellType::quad) std::swap(f.nodes[1], f.nodes[3]);
  else if (f.type == CellType::triangle) std::swap(f.nodes[1], f.nodes[2]);
  else {  // tri6: (0,1,2,3,4,5) -> (0,2,1,5,4,3)
    std::swap(f.nodes[1], f.nodes[2]);
    std::swap(f.nodes[3], f.nodes[5]);
  }
}

}  // namespace

std::vector<Face> boundary_faces(const MeshData& mesh, const std::vector<bool>& active) {
  std::map<std::vector<std::int64_t>, std::pair<Face, int>> seen;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (!active.empty() && !active[c]) continue;
    const auto conn = mesh.cell(c);
    const std::vector<std::vector<int>>* table = nullptr;
    CellType ft{};
    switch (mesh.cell_types[c]) {
      case CellType::hexahedron: table = &kHexFaces; ft = CellType::quad; break;
      case CellType::tetra: table = &kTetFaces; ft = CellType::triangle; break;
      case CellType::quadratic_tetra: table = &kTet10Faces; ft = CellType::quadratic_triangle; break;
      default: continue;
    }
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (auto n : conn) centroid += mesh.points[static_cast<std::size_t>(n)];
    centroid /= static_cast<double>(conn.size());
    for (const auto& lf : *table) {
      Face f;
      f.type = ft;
      f.count = static_cast<int>(lf.size());
      f.cell = c;
      for (int i = 0; i < f.count; ++i) f.nodes[i] = conn[static_cast<std::size_t>(lf[i])];
      // Insurance against unusual node orders: the normal must point away from the cell.
      Eigen::Vector3d fc = Eigen::Vector3d::Zero();
      const int corners = ft == CellType::quad ? 4 : 3;
      for (int i = 0; i < corners; ++i) fc += mesh.points[static_cast<std::size_t>(f.nodes[i])];
      fc /= corners;
      if (face_normal(mesh, f).dot(fc - centroid) < 0) flip(f);
      std::vector<std::int64_t> key(f.nodes.begin(), f.nodes.begin() + corners);
      std::sort(key.begin(), key.end());
      auto [it, inserted] = seen.try_emplace(key, f, 0);
      ++it->second.second;
    }
  }
  std::vector<Face> out;
  for (auto& [key, fc] : seen)
    if (fc.second == 1) out.push_back(fc.first);
  std::sort(out.begin(), out.end(), [](const Face& a, const Face& b) { return a.cell < b.cell; });
  return out;
}

}  // namespace stentsim::solver::fem
