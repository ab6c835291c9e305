// Tree input helpers (see tree_input.hpp).
#include "segmentation_io/tree_input.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "common/error.hpp"
#include "segmentation_io/surface_distance.hpp"

namespace stentsim::segmentation {

using Eigen::Vector3d;

Vector3d farthest_point_along_surface(const TriSurface& tree, const Vector3d& from, double inset) {
  auto pieces = connected_pieces(tree);
  std::size_t best = 0;
  double bd = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    SurfaceDistance d(pieces[i]);
    auto inside = inside_closed_surface(pieces[i], {from});
    double dist = inside[0] ? 0.0 : d.distance(from);
    if (dist < bd) bd = dist, best = i;
  }
  const TriSurface& s = pieces[best];
  const std::size_t n = s.points.size();
  std::vector<std::vector<std::pair<int, double>>> adj(n);
  std::vector<Vector3d> normal(n, Vector3d::Zero());
  for (const auto& t : s.triangles) {
    Vector3d a = (s.points[t[1]] - s.points[t[0]]).cross(s.points[t[2]] - s.points[t[0]]);
    for (int k = 0; k < 3; ++k) {
      int u = t[k], v = t[(k + 1) % 3];
      double w = (s.points[u] - s.points[v]).norm();
      adj[std::size_t(u)].push_back({v, w});
      adj[std::size_t(v)].push_back({u, w});
      normal[std::size_t(t[k])] += a;
    }
  }
  std::size_t start = 0;
  double sd = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < n; ++i)
    if ((s.points[i] - from).squaredNorm() < sd) sd = (s.points[i] - from).squaredNorm(), start = i;
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
  dist[start] = 0;
  q.push({0.0, int(start)});
  while (!q.empty()) {
    auto [d, u] = q.top();
    q.pop();
    if (d > dist[std::size_t(u)]) continue;
    for (auto [v, w] : adj[std::size_t(u)])
      if (d + w < dist[std::size_t(v)]) dist[std::size_t(v)] = d + w, q.push({d + w, v});
  }
  std::size_t far = start;
  for (std::size_t i = 0; i < n; ++i)
    if (std::isfinite(dist[i]) && dist[i] > dist[far]) far = i;
  const double sign = signed_volume(s) >= 0 ? 1.0 : -1.0;  // outward normals for a positively oriented surface
  return s.points[far] - inset * sign * normal[far].normalized();
}

TriSurface clip_region_of_interest(const TriSurface& lumen, const CenterlineResult& cl, double length,
                                   const StenosisRule& rule, std::optional<double> center, double& s0, double& s1,
                                   TaperedStenosis* site_out, StenosisProfile* profile_out) {
  const auto& P = cl.centerline.points;
  const auto& S = cl.centerline.point_data.at("Abscissas").values;
  const auto& R = cl.centerline.point_data.at("MaximumInscribedSphereRadius").values;
  const std::size_t n = P.size();
  if (n < 4) throw ComputeError("region of interest: the centerline has fewer than four points");
  const StenosisProfile prof = analyse_stenoses(S, R, rule);
  if (profile_out) *profile_out = prof;
  // The cut planes stay a reference radius inside the segment's ends (the
  // lesions are looked for further in, prof.lo to prof.hi).
  const double lo = S.front() + std::max(0.0, prof.reference_at(S.front())),
               hi = S.back() - std::max(0.0, prof.reference_at(S.back()));
  if (hi - lo < length)
    throw InputError(fmt::format("region of interest: {:.3g} mm asked, but the vessel segment offers {:.3g} mm between "
                                 "its ends (less a reference radius at each); set input.tree.roi_length to {:.3g} mm "
                                 "or less",
                                 length, std::max(0.0, hi - lo), std::floor(10 * std::max(0.0, hi - lo)) / 10));
  if (center && (*center < S.front() || *center > S.back()))
    throw InputError(fmt::format("input.tree.roi_center: {:.4g} mm lies outside the extracted segment (0 to {:.4g} mm "
                                 "along its centerline)", *center, S.back()));
  const Lesion* lesion = prof.most_severe();
  if (center) {  // the lesion that spans the given centre, else the centre itself
    lesion = prof.nearest(*center);
    if (lesion && !(*center >= lesion->start && *center <= lesion->end)) lesion = nullptr;
  }
  if (!lesion && !center)
    throw InputError(fmt::format("region of interest: {}; name the region's centre with input.tree.roi_center (an "
                                 "abscissa in mm along the extracted segment, e.g. {:.1f}) or lower "
                                 "stenosis.threshold_percent",
                                 prof.no_lesion_message(), prof.narrowest.abscissa));
  TaperedStenosis site = lesion ? static_cast<const TaperedStenosis&>(*lesion) : prof.narrowest;
  if (center && !lesion) {  // no lesion: the region sits where the user put it
    site.abscissa = *center;
    site.reference_radius = prof.reference_at(*center);
    site.radius = site.reference_radius;
  }
  if (site_out) *site_out = site;
  s0 = std::clamp(site.abscissa - 0.5 * length, lo, hi - length);
  s1 = s0 + length;
  auto frame = [&](double s, Vector3d& p, Vector3d& t) {
    std::size_t i = 1;
    while (i + 1 < n && S[i] < s) ++i;
    double a = (s - S[i - 1]) / std::max(1e-12, S[i] - S[i - 1]);
    p = (1 - a) * P[i - 1] + a * P[i];
    t = (P[std::min(i + 1, n - 1)] - P[i - 1]).normalized();
  };
  Vector3d p0, t0, p1, t1;
  frame(s0, p0, t0);
  frame(s1, p1, t1);
  TriSurface cut = clip_by_plane(clip_by_plane(lumen, p0, -t0), p1, t1);
  Vector3d site_point, site_tangent;
  frame(site.abscissa, site_point, site_tangent);
  // A curved vessel may cross a cut plane again elsewhere: keep the piece at the stenosis.
  auto parts = connected_pieces(cut);
  std::size_t best = 0;
  double bd = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < parts.size(); ++i) {
    SurfaceDistance d(parts[i]);
    double dist = d.distance(site_point);
    if (dist < bd) bd = dist, best = i;
  }
  return parts[best];
}

}  // namespace stentsim::segmentation
