// Outer wall synthesized from the lumen (see WallSynthesisOptions).
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "common/error.hpp"
#include "common/stenosis_site.hpp"
#include "segmentation_io/centerline.hpp"
#include "segmentation_io/polyline_frames.hpp"
#include "segmentation_io/segmentation_stage.hpp"

namespace stentsim::segmentation {

using Eigen::Vector3d;

TriSurface synthesize_wall(const TriSurface& lumen, const WallSynthesisOptions& o) {
  CenterlineOptions co;
  CenterlineResult cl = compute_centerline(lumen, co);
  const auto& pts = cl.centerline.points;
  const auto& r = cl.centerline.point_data.at("MaximumInscribedSphereRadius").values;
  const auto& S = cl.centerline.point_data.at("Abscissas").values;
  const std::size_t n = pts.size();
  // Healthy reference radius from the segments either side of the stenosis
  // (issue 3): the straight line fitted to the radius's upper envelope
  // (common/stenosis_site, the rule of the ROI and the placement), so a long
  // stenosis does not pull it down and a tapering vessel keeps its taper.
  // A whole-segment median would sit inside a stenosis longer than half the segment.
  const TaperedStenosis site = stenosis_discounting_taper(S, r, S.front() + r.front(), S.back() - r.back());
  auto reference_at = [&](std::size_t i) { return site.reference_radius + site.slope * (S[i] - site.abscissa); };
  Frames f = parallel_transport_frames(pts);
  // Lumen extent around each centerline point: farthest lumen vertex within a
  // slab normal to the centerline (an eccentric or oval lumen reaches beyond r).
  double edge = 0;
  for (const auto& t : lumen.triangles) edge += (lumen.points[t[1]] - lumen.points[t[0]]).norm();
  edge /= double(std::max<std::size_t>(1, lumen.triangles.size()));
  const double slab = std::max(co.spacing, edge);
  std::vector<double> extent(r.begin(), r.end());
  for (std::size_t i = 0; i < n; ++i)
    for (const auto& x : lumen.points) {
      Vector3d d = x - pts[i];
      double along = d.dot(f.tangent[i]);
      if (std::abs(along) > slab) continue;
      double radial = (d - along * f.tangent[i]).norm();
      if (radial < 4 * reference_at(i)) extent[i] = std::max(extent[i], radial);
    }
  const double Rref = site.reference_radius, t = o.wall_thickness;
  std::vector<double> R(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double ref = reference_at(i);
    R[i] = std::max(ref + t + o.remodeling * std::max(0.0, ref - r[i]), extent[i] + 0.5 * t);
  }
  // Smooth over ±1 mm so the outer wall does not copy the lumen's facets.
  std::vector<double> Rs(n);
  const int w = std::max(1, int(std::round(1.0 / co.spacing)));
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0;
    int c = 0;
    for (int k = -w; k <= w; ++k) {
      long j = long(i) + k;
      if (j < 0 || j >= long(n)) continue;
      sum += R[std::size_t(j)];
      ++c;
    }
    Rs[i] = std::max(sum / c, extent[i] + 0.5 * t);
  }
  const int N = o.circumferential_points;
  const double h = 2 * M_PI * (Rref + t) / N;
  const int step = std::max(1, int(std::round(h / co.spacing)));
  std::vector<std::size_t> stations;
  for (std::size_t i = 0; i < n; i += std::size_t(step)) stations.push_back(i);
  if (stations.back() != n - 1) stations.push_back(n - 1);
  TriSurface wall;
  for (std::size_t i : stations)
    for (int j = 0; j < N; ++j) {
      double th = 2 * M_PI * j / N;
      wall.points.push_back(pts[i] + Rs[i] * (std::cos(th) * f.normal[i] + std::sin(th) * f.binormal[i]));
    }
  const int rings = int(stations.size());
  for (int k = 0; k + 1 < rings; ++k)
    for (int j = 0; j < N; ++j) {
      int a = k * N + j, b = k * N + (j + 1) % N, c = (k + 1) * N + j, d = (k + 1) * N + (j + 1) % N;
      wall.triangles.push_back({a, b, d});
      wall.triangles.push_back({a, d, c});
    }
  return wall;
}

}  // namespace stentsim::segmentation
