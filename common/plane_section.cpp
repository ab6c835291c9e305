// Plane cuts and ray hits (common/plane_section.hpp).
#include "common/plane_section.hpp"

#include <cmath>
#include <limits>

namespace stentsim {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::vector<std::pair<Vector2d, Vector2d>> plane_cut(const MeshData& surf, const Vector3d& o, const Vector3d& t,
                                                     const Vector3d& n, const Vector3d& b) {
  std::vector<double> d(surf.points.size());
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = (surf.points[i] - o).dot(t);
  std::vector<std::pair<Vector2d, Vector2d>> segs;
  auto to2 = [&](const Vector3d& x) { return Vector2d((x - o).dot(n), (x - o).dot(b)); };
  for (std::size_t c = 0; c < surf.num_cells(); ++c) {
    const auto ct = surf.cell_types[c];
    if (ct != CellType::triangle && ct != CellType::quad) continue;
    auto nodes = surf.cell(c);
    std::vector<Vector2d> hits;
    for (std::size_t e = 0; e < nodes.size(); ++e) {
      auto i = std::size_t(nodes[e]), j = std::size_t(nodes[(e + 1) % nodes.size()]);
      if ((d[i] < 0) == (d[j] < 0)) continue;
      const double a = d[i] / (d[i] - d[j]);
      hits.push_back(to2(surf.points[i] + a * (surf.points[j] - surf.points[i])));
    }
    if (hits.size() >= 2) segs.emplace_back(hits[0], hits[1]);
  }
  return segs;
}

double ray_hit(const std::vector<std::pair<Vector2d, Vector2d>>& segs, const Vector2d& dir) {
  double best = std::numeric_limits<double>::quiet_NaN();
  for (const auto& [p, q] : segs) {
    const Vector2d e = q - p;
    const double den = dir.x() * (-e.y()) - dir.y() * (-e.x());
    if (std::abs(den) < 1e-14) continue;
    // r dir = p + u e  ->  [dir, -e] [r, u]^T = p
    const double r = (p.x() * (-e.y()) - p.y() * (-e.x())) / den;
    const double u = (dir.x() * p.y() - dir.y() * p.x()) / den;
    if (u < -1e-9 || u > 1 + 1e-9 || r <= 0) continue;
    if (!(r >= best)) best = r;
  }
  return best;
}

}  // namespace stentsim
