// Area of the lumen cut by a plane normal to the centerline (VMTK's
// "CenterlineSectionArea"): the cut segments are chained into loops through
// the mesh edges they cross, and the loop around the centerline point counts.
#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "segmentation_io/centerline.hpp"

namespace stentsim::segmentation {

using Eigen::Vector3d;

double section_area(const TriSurface& s, const Vector3d& p, const Vector3d& normal) {
  const Vector3d t = normal.normalized();
  using Key = std::pair<int, int>;
  std::map<Key, Vector3d> where;            // crossing point per mesh edge
  std::map<Key, std::vector<Key>> links;    // cut segments between crossings
  auto key = [](int a, int b) { return Key{std::min(a, b), std::max(a, b)}; };
  for (const auto& tri : s.triangles) {
    double d[3];
    for (int k = 0; k < 3; ++k) {
      d[k] = (s.points[tri[k]] - p).dot(t);
      if (d[k] == 0) d[k] = 1e-300;  // on the plane: count as above (consistently for all triangles)
    }
    Key found[2];
    int count = 0;
    for (int k = 0; k < 3; ++k) {
      int a = tri[k], b = tri[(k + 1) % 3];
      double da = d[k], db = d[(k + 1) % 3];
      if ((da < 0) == (db < 0)) continue;
      Key e = key(a, b);
      if (!where.count(e)) {
        double w = da / (da - db);
        where[e] = s.points[a] + w * (s.points[b] - s.points[a]);
      }
      if (count < 2) found[count++] = e;
    }
    if (count == 2) {
      links[found[0]].push_back(found[1]);
      links[found[1]].push_back(found[0]);
    }
  }
  // Walk loops; keep the one that winds around p with the smallest area.
  const Vector3d e1 = t.unitOrthogonal(), e2 = t.cross(e1);
  std::map<Key, bool> seen;
  double best = 0;
  for (const auto& [start, _] : links) {
    if (seen[start]) continue;
    std::vector<Key> loop{start};
    seen[start] = true;
    Key prev = start, cur = links[start].front();
    bool closed = false;
    while (true) {
      if (cur == start) {
        closed = true;
        break;
      }
      if (seen[cur]) break;
      seen[cur] = true;
      loop.push_back(cur);
      const auto& nb = links[cur];
      if (nb.size() != 2) break;  // boundary of an open surface: not a closed section
      Key next = nb[0] == prev ? nb[1] : nb[0];
      prev = cur;
      cur = next;
    }
    if (!closed || loop.size() < 3) continue;
    double area = 0, winding = 0;
    for (std::size_t i = 0; i < loop.size(); ++i) {
      Vector3d a = where[loop[i]] - p, b = where[loop[(i + 1) % loop.size()]] - p;
      Eigen::Vector2d a2(a.dot(e1), a.dot(e2)), b2(b.dot(e1), b.dot(e2));
      area += 0.5 * (a2.x() * b2.y() - a2.y() * b2.x());
      winding += std::atan2(a2.x() * b2.y() - a2.y() * b2.x(), a2.dot(b2));
    }
    if (std::abs(winding) > M_PI && (best == 0 || std::abs(area) < best)) best = std::abs(area);
  }
  return best;
}

}  // namespace stentsim::segmentation
