// Centerline computation: Voronoi minimal path, resampling, centring, arrays.
#include "segmentation_io/centerline.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <queue>

#include "common/error.hpp"
#include "common/stenosis_site.hpp"
#include "segmentation_io/medial_axis.hpp"
#include "segmentation_io/polyline_frames.hpp"
#include "segmentation_io/surface_distance.hpp"

namespace stentsim::segmentation {

using Eigen::Vector3d;

namespace {

// An open end: its centroid and the unit normal of its plane pointing out of the tube.
struct End {
  Vector3d centroid, outward;
  double radius = 0;
};

End end_of(const TriSurface& s, const BoundaryLoop& loop) {
  // Newell's normal of the loop polygon.
  Vector3d n = Vector3d::Zero();
  for (std::size_t i = 0; i < loop.vertices.size(); ++i) {
    const auto& a = s.points[loop.vertices[i]];
    const auto& b = s.points[loop.vertices[(i + 1) % loop.vertices.size()]];
    n += a.cross(b);
  }
  n.normalize();
  // Orient away from the surface: the vertices of triangles touching the loop
  // but not on it lie on the inner side.
  std::vector<bool> on_loop(s.points.size(), false);
  for (int v : loop.vertices) on_loop[v] = true;
  Vector3d inner = Vector3d::Zero();
  int count = 0;
  for (const auto& t : s.triangles) {
    bool touches = on_loop[t[0]] || on_loop[t[1]] || on_loop[t[2]];
    if (!touches) continue;
    for (int v : t)
      if (!on_loop[v]) {
        inner += s.points[v];
        ++count;
      }
  }
  if (count > 0 && (inner / count - loop.centroid).dot(n) > 0) n = -n;
  return {loop.centroid, n, loop.mean_radius};
}

int nearest_node(const MedialGraph& g, const Vector3d& p) {
  int best = -1;
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < g.centers.size(); ++i) {
    double e = (g.centers[i] - p).squaredNorm();
    if (e < d) {
      d = e;
      best = int(i);
    }
  }
  return best;
}

// Dijkstra with cost ∫ 1/R ds along straight Voronoi edges (trapezoid rule).
std::vector<int> minimal_path(const MedialGraph& g, int from, int to) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> cost(g.centers.size(), inf);
  std::vector<int> prev(g.centers.size(), -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  cost[from] = 0;
  queue.emplace(0.0, from);
  while (!queue.empty()) {
    auto [c, i] = queue.top();
    queue.pop();
    if (c > cost[i]) continue;
    if (i == to) break;
    for (int j : g.neighbours[i]) {
      double w = (g.centers[j] - g.centers[i]).norm() * 0.5 * (1 / g.radius[i] + 1 / g.radius[j]);
      if (c + w < cost[j]) {
        cost[j] = c + w;
        prev[j] = i;
        queue.emplace(cost[j], j);
      }
    }
  }
  if (!std::isfinite(cost[to])) return {};
  std::vector<int> path;
  for (int i = to; i != -1; i = prev[i]) path.push_back(i);
  std::reverse(path.begin(), path.end());
  return path;
}

// Maximum of the distance to the surface in the plane (p, t): Nelder–Mead on
// the two in-plane coordinates (the distance is not smooth at its maximum,
// where it touches the surface along a circle, so no gradient method).
Vector3d centre_in_plane(const SurfaceDistance& dist, const Vector3d& p, const Vector3d& t, double r) {
  Vector3d e1 = t.unitOrthogonal(), e2 = t.cross(e1);
  auto f = [&](const Eigen::Vector2d& x) { return -dist.distance(p + x[0] * e1 + x[1] * e2); };
  const double step = std::max(0.2 * r, 1e-6);
  Eigen::Vector2d x[3] = {{0, 0}, {step, 0}, {0, step}};
  double fx[3] = {f(x[0]), f(x[1]), f(x[2])};
  for (int it = 0; it < 200; ++it) {
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int a, int b) { return fx[a] < fx[b]; });
    int b = order[0], m = order[1], w = order[2];
    double size = std::max((x[m] - x[b]).norm(), (x[w] - x[b]).norm());
    if (size < 1e-4 * r) break;  // 0.01 % of the radius: far below the 2 % target
    Eigen::Vector2d c = 0.5 * (x[b] + x[m]);
    Eigen::Vector2d xr = c + (c - x[w]);
    double fr = f(xr);
    if (fr < fx[b]) {
      Eigen::Vector2d xe = c + 2 * (c - x[w]);
      double fe = f(xe);
      if (fe < fr) x[w] = xe, fx[w] = fe;
      else x[w] = xr, fx[w] = fr;
    } else if (fr < fx[m]) {
      x[w] = xr, fx[w] = fr;
    } else {
      Eigen::Vector2d xc = fr < fx[w] ? Eigen::Vector2d(c + 0.5 * (xr - c)) : Eigen::Vector2d(c + 0.5 * (x[w] - c));
      double fc = f(xc);
      if (fc < std::min(fr, fx[w])) {
        x[w] = xc, fx[w] = fc;
      } else {  // shrink towards the best
        for (int k : {m, w}) {
          x[k] = x[b] + 0.5 * (x[k] - x[b]);
          fx[k] = f(x[k]);
        }
      }
    }
  }
  int best = int(std::min_element(fx, fx + 3) - fx);
  return p + x[best][0] * e1 + x[best][1] * e2;
}

std::vector<Vector3d> tangents_over_radius(const std::vector<Vector3d>& p, const std::vector<double>& r, double h) {
  // Tangent from neighbours about half a radius away on either side: the
  // resampled path still carries the Voronoi zig-zag at the scale of h.
  const int n = int(p.size());
  std::vector<Vector3d> t(n);
  for (int i = 0; i < n; ++i) {
    int k = std::max(1, int(std::round(0.5 * r[i] / h)));
    int a = std::max(0, i - k), b = std::min(n - 1, i + k);
    t[i] = (p[b] - p[a]).normalized();
  }
  return t;
}

// Beyond an open end: on the outer side of its plane and near it (a curved
// vessel may come back to the far side of the plane elsewhere).
bool beyond_ends(const Vector3d& x, const std::vector<End>& ends) {
  for (const auto& e : ends)
    if ((x - e.centroid).dot(e.outward) > 0 && (x - e.centroid).norm() < 3 * e.radius) return true;
  return false;
}

}  // namespace

CenterlineResult compute_centerline(const MeshData& lumen, const CenterlineOptions& o) {
  return compute_centerline(surface_from_mesh(lumen, "lumen"), o);
}

CenterlineResult compute_centerline(const TriSurface& s, const CenterlineOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!(o.spacing >= kMinCenterlineSpacing && o.spacing <= kMaxCenterlineSpacing))
    throw InputError(fmt::format("centerline: spacing {:g} mm is outside {:g} to {:g} mm", o.spacing, kMinCenterlineSpacing,
                                 kMaxCenterlineSpacing));
  CenterlineResult res;

  // Ends.
  std::vector<End> ends;
  Vector3d from_point, to_point;
  if (o.source_point && o.target_point) {
    from_point = *o.source_point;
    to_point = *o.target_point;
  } else if (o.source_point || o.target_point) {
    throw InputError("centerline: give both source and target points, or neither (then the two open ends are used)");
  } else {
    auto loops = boundary_loops(s);
    if (loops.size() != 2) {
      std::string list;
      for (const auto& l : loops)
        list += fmt::format("\n  open end at ({:.3f}, {:.3f}, {:.3f}) mm, radius {:.3f} mm", l.centroid.x(),
                            l.centroid.y(), l.centroid.z(), l.mean_radius);
      throw InputError(fmt::format("centerline: the lumen has {} open ends; exactly two are needed to find the "
                                   "centerline automatically; give source and target points instead{}",
                                   loops.size(), list));
    }
    ends = {end_of(s, loops[0]), end_of(s, loops[1])};
    from_point = ends[0].centroid;
    to_point = ends[1].centroid;
  }

  // 1–2. Voronoi graph and minimal path.
  MedialGraph g = interior_voronoi_graph(s);
  res.voronoi_nodes = g.centers.size();
  if (g.centers.empty()) throw ComputeError("centerline: no interior Voronoi node; are the lumen normals outward?");
  int a = nearest_node(g, from_point), b = nearest_node(g, to_point);
  std::vector<int> nodes = minimal_path(g, a, b);
  if (nodes.empty())
    throw ComputeError(fmt::format("centerline: the interior Voronoi diagram does not connect the two ends "
                                   "({:.3f}, {:.3f}, {:.3f}) and ({:.3f}, {:.3f}, {:.3f}); is the lumen pinched off?",
                                   from_point.x(), from_point.y(), from_point.z(), to_point.x(), to_point.y(),
                                   to_point.z()));
  std::vector<Vector3d> path;
  if (!ends.empty()) path.push_back(ends[0].centroid);
  for (int i : nodes)
    if (!beyond_ends(g.centers[i], ends)) path.push_back(g.centers[i]);
  if (!ends.empty()) path.push_back(ends[1].centroid);
  if (path.size() < 2) throw ComputeError("centerline: the minimal path is empty");

  // 3–4. Resample and centre.
  SurfaceDistance dist(s);
  const double h = o.spacing;
  std::vector<Vector3d> pts = resample_polyline(path, h);
  for (int pass = 0; pass < o.centering_passes; ++pass) {
    std::vector<double> r(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) r[i] = dist.distance(pts[i]);
    auto t = tangents_over_radius(pts, r, h);
    const std::size_t first = ends.empty() ? 0 : 1, last = ends.empty() ? pts.size() : pts.size() - 1;
    for (std::size_t i = first; i < last; ++i) {
      Vector3d q = centre_in_plane(dist, pts[i], t[i], r[i]);
      if ((q - pts[i]).norm() < 0.75 * r[i] && !beyond_ends(q, ends)) pts[i] = q;
    }
    pts = resample_polyline(pts, h);
  }

  // 4b. Smoothing with a bounded displacement. A real lumen's Voronoi path
  // kinks at eccentric lesions and junctions, and sections normal to a kink
  // meet inside the wall whatever their spacing: the curve the mesh and the
  // fibers cut along is smoothed by a non-shrinking filter that damps
  // wavelengths below about 4 smoothing_length (polyline_frames), each point
  // kept within smoothing_bound × its inscribed radius of the centred path.
  // Smooth vessels keep their shape (an arc of 5 mm radius moves by
  // micrometres).
  if (o.smoothing_length > 0 && pts.size() > 2) {
    std::vector<double> bound(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) bound[i] = o.smoothing_bound * dist.distance(pts[i]);
    res.smoothing_displacement_max = smooth_with_bounded_displacement(pts, bound, o.smoothing_length / h);
    pts = resample_polyline(pts, h);
  }

  // 5. Arrays.
  const std::size_t n = pts.size();
  std::vector<double> radius(n), abscissa = cumulative_length(pts);
  for (std::size_t i = 0; i < n; ++i) radius[i] = dist.distance(pts[i]);
  Frames frames = parallel_transport_frames(pts);
  MeshData& cl = res.centerline;
  cl.points = pts;
  std::vector<std::int64_t> ids(n);
  for (std::size_t i = 0; i < n; ++i) ids[i] = std::int64_t(i);
  cl.add_cell(CellType::polyline, ids);
  DataArray R{1, radius}, A{1, abscissa}, N{3, {}}, area{1, {}};
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) N.values.push_back(frames.normal[i][c]);
    area.values.push_back(section_area(s, pts[i], frames.tangent[i]));
  }
  cl.point_data["MaximumInscribedSphereRadius"] = R;
  cl.point_data["Abscissas"] = A;
  cl.point_data["ParallelTransportNormals"] = N;
  cl.point_data["CenterlineSectionArea"] = area;
  cl.field_text["units"] = "mm";
  cl.field_text["centerline_method"] =
      "Voronoi minimal path (cost 1/R) between the ends, resampled and centred in normal planes";

  // Lesions and the reference line by the one stenosis rule
  // (common/stenosis_site, as the segmentation ROI, the wall synthesis and the
  // device placement); the site is the most severe lesion, or the narrowest
  // point relative to the reference when there is none.
  res.length = abscissa.back();
  res.stenoses = analyse_stenoses(abscissa, radius, o.stenosis);
  for (Lesion& l : res.stenoses.lesions) {
    const std::size_t k = std::size_t(std::lower_bound(abscissa.begin(), abscissa.end(), l.abscissa) - abscissa.begin());
    const Eigen::Vector3d& x = pts[std::min(k, n - 1)];
    l.point = std::array<double, 3>{x.x(), x.y(), x.z()};
  }
  const Lesion* worst = res.stenoses.most_severe();
  const TaperedStenosis site = worst ? static_cast<const TaperedStenosis&>(*worst) : res.stenoses.narrowest;
  auto ref_at = [&](double s) { return res.stenoses.reference_at(s); };
  std::size_t imin = std::size_t(std::find(abscissa.begin(), abscissa.end(), site.abscissa) - abscissa.begin());
  // Parabola through the smallest ratio r / r_ref and its neighbours for a sub-sample site.
  res.stenosis_abscissa = abscissa[imin];
  res.min_radius = radius[imin];
  res.stenosis_point = pts[imin];
  if (imin > 0 && imin + 1 < n) {
    double y0 = radius[imin - 1] / ref_at(abscissa[imin - 1]), y1 = radius[imin] / ref_at(abscissa[imin]),
           y2 = radius[imin + 1] / ref_at(abscissa[imin + 1]);
    double den = y0 - 2 * y1 + y2;
    if (den > 0) {
      double x = std::clamp(0.5 * (y0 - y2) / den, -1.0, 1.0);
      double hs = x >= 0 ? abscissa[imin + 1] - abscissa[imin] : abscissa[imin] - abscissa[imin - 1];
      res.stenosis_abscissa = abscissa[imin] + x * hs;
      res.min_radius = (y1 - 0.25 * (y0 - y2) * x) * ref_at(res.stenosis_abscissa);
      res.stenosis_point = pts[imin] + x * (x >= 0 ? pts[imin + 1] - pts[imin] : pts[imin] - pts[imin - 1]);
    }
  }
  res.reference_radius = o.reference_radius ? *o.reference_radius : ref_at(res.stenosis_abscissa);
  res.reference_taper = site.slope;
  res.stenosis_percent_diameter = 100 * (1 - res.min_radius / res.reference_radius);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace stentsim::segmentation
