#include "segmentation_io/branch_extraction.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

#include "common/error.hpp"
#include "common/log.hpp"
#include "segmentation_io/surface_distance.hpp"

namespace stentsim::segmentation {

using Eigen::Vector3d;

TriSurface clip_by_plane(const TriSurface& s, const Vector3d& p, const Vector3d& normal) {
  const Vector3d n = normal.normalized();
  TriSurface out;
  std::vector<int> kept(s.points.size(), -1);
  std::vector<double> d(s.points.size());
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    d[i] = (s.points[i] - p).dot(n);
    if (d[i] == 0) d[i] = -1e-300;  // on the plane: inside (consistently)
  }
  auto vertex = [&](int v) {
    if (kept[v] < 0) kept[v] = int(out.points.size()), out.points.push_back(s.points[v]);
    return kept[v];
  };
  std::map<std::pair<int, int>, int> cut;
  auto crossing = [&](int a, int b) {
    auto key = std::make_pair(std::min(a, b), std::max(a, b));
    auto it = cut.find(key);
    if (it != cut.end()) return it->second;
    double w = d[a] / (d[a] - d[b]);
    int id = int(out.points.size());
    out.points.push_back(s.points[a] + w * (s.points[b] - s.points[a]));
    cut[key] = id;
    return id;
  };
  for (const auto& t : s.triangles) {
    int inside = (d[t[0]] < 0) + (d[t[1]] < 0) + (d[t[2]] < 0);
    if (inside == 3) {
      out.triangles.push_back({vertex(t[0]), vertex(t[1]), vertex(t[2])});
    } else if (inside > 0) {
      // Rotate so that the lone vertex (inside when 1, outside when 2) comes first.
      int k = 0;
      for (int j = 0; j < 3; ++j)
        if ((d[t[j]] < 0) == (inside == 1)) k = j;
      int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
      int ab = crossing(a, b), ca = crossing(c, a);
      if (inside == 1) {
        out.triangles.push_back({vertex(a), ab, ca});
      } else {
        int vb = vertex(b), vc = vertex(c);
        out.triangles.push_back({ab, vb, vc});
        out.triangles.push_back({ab, vc, ca});
      }
    }
  }
  return out;
}

std::vector<TriSurface> connected_pieces(const TriSurface& s) {
  std::map<std::pair<int, int>, std::vector<int>> edge_tris;
  for (std::size_t i = 0; i < s.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      int a = s.triangles[i][k], b = s.triangles[i][(k + 1) % 3];
      edge_tris[{std::min(a, b), std::max(a, b)}].push_back(int(i));
    }
  std::vector<int> piece(s.triangles.size(), -1);
  std::vector<TriSurface> out;
  for (std::size_t seed = 0; seed < s.triangles.size(); ++seed) {
    if (piece[seed] >= 0) continue;
    int id = int(out.size());
    TriSurface part;
    std::map<int, int> index;
    std::vector<int> stack{int(seed)};
    piece[seed] = id;
    while (!stack.empty()) {
      int t = stack.back();
      stack.pop_back();
      std::array<int, 3> tri;
      for (int k = 0; k < 3; ++k) {
        int v = s.triangles[t][k];
        auto [it, fresh] = index.emplace(v, int(part.points.size()));
        if (fresh) part.points.push_back(s.points[v]);
        tri[k] = it->second;
        int w = s.triangles[t][(k + 1) % 3];
        for (int u : edge_tris[{std::min(v, w), std::max(v, w)}])
          if (piece[u] < 0) piece[u] = id, stack.push_back(u);
      }
      part.triangles.push_back(tri);
    }
    out.push_back(std::move(part));
  }
  std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) { return surface_area(x) > surface_area(y); });
  return out;
}

BranchSegment extract_branch(const TriSurface& tree, const Vector3d& a, const Vector3d& b, const BranchOptions& o) {
  // The piece (separate vessel tree) holding both points; trees of a
  // segmentation may overlap (XCAT's do), so the one with both points inside
  // and then the nearest wins.
  auto pieces = connected_pieces(tree);
  int best = -1, containing = 0;
  double best_score = 1e300, da = 0, db = 0;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    SurfaceDistance dist(pieces[i]);
    auto inside = inside_closed_surface(pieces[i], {a, b});
    double sa = inside[0] ? 0 : dist.distance(a), sb = inside[1] ? 0 : dist.distance(b);
    if (inside[0] && inside[1]) ++containing;
    if (sa + sb < best_score) best_score = sa + sb, best = int(i), da = sa, db = sb;
  }
  auto where = [](const Vector3d& p) { return fmt::format("({:.3f}, {:.3f}, {:.3f}) mm", p.x(), p.y(), p.z()); };
  if (best < 0 || da > 1.0 || db > 1.0)
    throw InputError(fmt::format("branch extraction: the points {} and {} do not both lie in (or within 1 mm of) one "
                                 "vessel tree of the surface", where(a), where(b)));
  if (containing > 1)
    log::warn("branch extraction: {} separate surfaces of the tree contain both points (overlapping trees); the "
              "largest is used", containing);
  const TriSurface& piece = pieces[std::size_t(best)];

  // Centerline on the whole tree piece between the points.
  CenterlineOptions co;
  co.spacing = o.spacing;
  co.source_point = a;
  co.target_point = b;
  // The side-branch cuts follow the centred Voronoi path itself (the
  // smoothed curve, which may leave it by a third of a radius, moved a cut
  // onto a junction's rim: non-manifold caps on the XCAT tree).
  co.smoothing_length = 0;
  CenterlineResult full = compute_centerline(piece, co);
  const auto& P = full.centerline.points;
  const auto& R = full.centerline.point_data.at("MaximumInscribedSphereRadius").values;
  const std::size_t n = P.size();
  if (n < 4) throw ComputeError("branch extraction: the points are too close together");
  // Planar cuts a little inside the ends (the ends of the path may sit in caps).
  auto at_abscissa = [&](double s) {
    std::size_t i = 0;
    while (i + 2 < n && (i + 1) * o.spacing < s) ++i;
    return i;
  };
  std::size_t i0 = at_abscissa(std::max(o.end_margin, R.front())), i1 = n - 1 - at_abscissa(std::max(o.end_margin, R.back()));
  if (i1 <= i0 + 2) throw ComputeError("branch extraction: the segment between the points is shorter than its radius");
  Vector3d t0 = (P[i0 + 1] - P[i0 - 1]).normalized(), t1 = (P[i1 + 1] - P[i1 - 1]).normalized();
  TriSurface cut = clip_by_plane(clip_by_plane(piece, P[i0], -t0), P[i1], t1);

  // Keep the piece of the cut that contains the path, then cut side branches.
  auto parts = connected_pieces(cut);
  TriSurface seg;
  double near = 1e300;
  for (auto& part : parts) {
    SurfaceDistance dist(part);
    double d = dist.distance(P[(i0 + i1) / 2]);
    if (d < near) near = d, seg = std::move(part);
  }
  std::vector<std::array<int, 3>> keep;
  for (const auto& t : seg.triangles) {
    Vector3d c = (seg.points[t[0]] + seg.points[t[1]] + seg.points[t[2]]) / 3.0;
    double dmin = 1e300;
    std::size_t imin = 0;
    for (std::size_t i = i0; i <= i1; ++i) {
      double d = (P[i] - c).squaredNorm();
      if (d < dmin) dmin = d, imin = i;
    }
    if (std::sqrt(dmin) <= o.side_branch_cut * R[imin]) keep.push_back(t);
  }
  seg.triangles = std::move(keep);
  // Cutting may leave slivers hanging by a vertex: keep the main piece again.
  seg = connected_pieces(seg).front();

  // Open boundaries: the two planar ends (those nearest P[i0], P[i1]) stay
  // open; side-branch openings are capped.
  auto loops = boundary_loops(seg);
  if (loops.size() < 2) throw ComputeError("branch extraction: the cut segment has fewer than two open ends");
  auto closest = [&](const Vector3d& p) {
    std::size_t k = 0;
    for (std::size_t i = 1; i < loops.size(); ++i)
      if ((loops[i].centroid - p).norm() < (loops[k].centroid - p).norm()) k = i;
    return k;
  };
  std::size_t e0 = closest(P[i0]), e1 = closest(P[i1]);
  std::vector<BoundaryLoop> side;
  for (std::size_t i = 0; i < loops.size(); ++i)
    if (i != e0 && i != e1) side.push_back(loops[i]);
  BranchSegment out;
  out.piece = best;
  out.side_branches_cut = int(side.size());
  out.lumen = capped(seg, side);
  // Compact unused points.
  {
    std::vector<int> index(out.lumen.points.size(), -1);
    std::vector<Vector3d> used;
    for (auto& t : out.lumen.triangles)
      for (int& v : t) {
        if (index[v] < 0) index[v] = int(used.size()), used.push_back(out.lumen.points[v]);
        v = index[v];
      }
    out.lumen.points = std::move(used);
  }
  CenterlineOptions so;
  so.spacing = o.spacing;
  out.centerline = compute_centerline(out.lumen, so);
  log::info("branch: {:.1f} mm segment, {} side branches cut, {} triangles", out.centerline.length,
            out.side_branches_cut, out.lumen.num_triangles());
  return out;
}

}  // namespace stentsim::segmentation
