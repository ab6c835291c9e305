// Outer wall synthesized from the lumen (see WallSynthesisOptions; DESIGN.md §8).
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "common/error.hpp"
#include "common/log.hpp"
#include "common/plane_section.hpp"
#include "common/stenosis_site.hpp"
#include "segmentation_io/centerline.hpp"
#include "segmentation_io/polyline_frames.hpp"
#include "segmentation_io/segmentation_stage.hpp"

namespace stentsim::segmentation {

using Eigen::Vector2d;
using Eigen::Vector3d;

double layer_rule_thickness(double reference_diameter, double nominal_intima) {
  // Media and adventitia are 0.0786 and 0.136 of the outer diameter
  // D_ref + 2t (Holzapfel et al. 2005, the mesh stage's ratios), the intima
  // t_I: t = t_I + 0.2146 (D_ref + 2t)  =>  t = (t_I + 0.2146 D_ref) / 0.5708.
  return (nominal_intima + 0.2146 * reference_diameter) / 0.5708;
}

namespace {

constexpr double kPi = std::numbers::pi;

/// Moving average along the stations (±half_window samples), per ray.
std::vector<std::vector<double>> smooth_along(const std::vector<std::vector<double>>& v, int half_window) {
  std::vector<std::vector<double>> out = v;
  const int n = int(v.size());
  for (int i = 0; i < n; ++i)
    for (std::size_t j = 0; j < v[std::size_t(i)].size(); ++j) {
      double sum = 0;
      int c = 0;
      for (int k = std::max(0, i - half_window); k <= std::min(n - 1, i + half_window); ++k) sum += v[std::size_t(k)][j], ++c;
      out[std::size_t(i)][j] = sum / c;
    }
  return out;
}

/// Outer boundary of the disk-dilation of the star-shaped contour q (one
/// radius per ray at angles 2πj/N) by t, as one radius per ray: the
/// dilation of a star-shaped set is star-shaped about the same point (a
/// Minkowski sum of two sets star-shaped about 0), so along each ray it is
/// one interval, ending at the farthest point of the disks of radius t about
/// the contour (sampled `sub` times per edge) that the ray meets. A distance
/// level set never folds, unlike an offset along normals at a concave rim.
std::vector<double> dilate(const std::vector<double>& q, double t, int sub) {
  const std::size_t N = q.size();
  std::vector<Vector2d> pts;
  pts.reserve(N * std::size_t(sub));
  for (std::size_t j = 0; j < N; ++j) {
    const double a0 = 2 * kPi * double(j) / double(N), a1 = 2 * kPi * double(j + 1) / double(N);
    const Vector2d p0 = q[j] * Vector2d(std::cos(a0), std::sin(a0)), p1 = q[(j + 1) % N] * Vector2d(std::cos(a1), std::sin(a1));
    for (int k = 0; k < sub; ++k) pts.push_back(p0 + (p1 - p0) * (double(k) / sub));
  }
  std::vector<double> w(N, 0.0);
  for (std::size_t j = 0; j < N; ++j) {
    const double a = 2 * kPi * double(j) / double(N);
    const Vector2d d(std::cos(a), std::sin(a));
    double best = q[j] + t;  // the ray's own contour point
    for (const Vector2d& p : pts) {
      const double along = p.dot(d), perp = std::abs(p.x() * d.y() - p.y() * d.x());
      if (perp < t) best = std::max(best, along + std::sqrt(t * t - perp * perp));
    }
    w[j] = best;
  }
  return w;
}

/// Fills NaN entries of one station's rays by periodic linear interpolation
/// between the nearest valid rays; false when fewer than half are valid.
bool fill_around(std::vector<double>& r) {
  const int N = int(r.size());
  int valid = 0;
  for (double v : r) valid += std::isnan(v) ? 0 : 1;
  if (2 * valid < N) return false;
  std::vector<double> out = r;
  for (int j = 0; j < N; ++j) {
    if (!std::isnan(r[std::size_t(j)])) continue;
    int a = 1, b = 1;
    while (std::isnan(r[std::size_t(((j - a) % N + N) % N)])) ++a;
    while (std::isnan(r[std::size_t((j + b) % N)])) ++b;
    const double ra = r[std::size_t(((j - a) % N + N) % N)], rb = r[std::size_t((j + b) % N)];
    out[std::size_t(j)] = ra + (rb - ra) * double(a) / double(a + b);
  }
  r = out;
  return true;
}

}  // namespace

TriSurface synthesize_wall(const TriSurface& lumen, const WallSynthesisOptions& o, Summary& summary,
                           const CenterlineResult* given) {
  CenterlineResult own;
  if (!given) {
    CenterlineOptions co;
    co.stenosis = o.stenosis;
    own = compute_centerline(lumen, co);
  }
  const CenterlineResult& cl = given ? *given : own;
  const auto& pts = cl.centerline.points;
  const auto& r = cl.centerline.point_data.at("MaximumInscribedSphereRadius").values;
  const auto& S = cl.centerline.point_data.at("Abscissas").values;
  const std::size_t n = pts.size();
  const StenosisProfile& prof = cl.stenoses;
  const Frames f = parallel_transport_frames(pts);
  const MeshData lumen_mesh = mesh_from_surface(lumen);
  const int N = o.circumferential_points;

  // Stations along the lumen centerline, one every station_spacing.
  std::vector<std::size_t> st;
  const double h = std::max(o.station_spacing, S.back() / 4000.0);
  for (std::size_t i = 0; i < n; ++i)
    if (st.empty() || S[i] - S[st.back()] >= h - 1e-9) st.push_back(i);
  if (st.back() != n - 1) {
    if (S[n - 1] - S[st.back()] < 0.5 * h && st.size() > 1) st.back() = n - 1;
    else st.push_back(n - 1);
  }
  const std::size_t ns = st.size();
  auto ref_at = [&](std::size_t i) { return std::max(prof.reference_at(S[i]), r[i]); };
  auto thickness_at = [&](std::size_t i) {
    return o.wall_thickness ? *o.wall_thickness : layer_rule_thickness(2 * ref_at(i), o.nominal_intima);
  };

  // 1. The lumen's polar contour at each station (nearest hit per ray),
  // enveloping the planes halfway to the neighbouring stations too (their
  // rays expressed in the station's frame), so a lumen that bulges between
  // two sections (a side-branch cap) stays inside the wall lofted through
  // them. A ray that meets nothing, or meets the surface only beyond 3 r_ref
  // (another part of a curved vessel, or through an open stub), is missing.
  std::vector<std::vector<double>> rho(ns, std::vector<double>(std::size_t(N)));
  std::size_t missing = 0, flared = 0;
  auto contour = [&](std::size_t i) {
    const auto cut = plane_cut(lumen_mesh, pts[i], f.tangent[i], f.normal[i], f.binormal[i]);
    std::vector<double> out(static_cast<std::size_t>(N));
    for (int j = 0; j < N; ++j) {
      const double a = 2 * kPi * j / N;
      const double v = ray_hit(cut, Vector2d(std::cos(a), std::sin(a)));
      out[std::size_t(j)] = v <= 3 * ref_at(i) ? v : std::numeric_limits<double>::quiet_NaN();
    }
    return out;
  };
  // The half-way contours, each shared by the two stations either side.
  std::vector<std::vector<double>> halfway(ns > 0 ? ns - 1 : 0);
  for (std::size_t k = 0; k + 1 < ns; ++k) halfway[k] = contour((st[k] + st[k + 1]) / 2);
  for (std::size_t k = 0; k < ns; ++k) {
    const std::size_t i = st[k];
    rho[k] = contour(i);
    for (std::size_t side = 0; side < 2; ++side) {
      if ((side == 0 && k == 0) || (side == 1 && k + 1 == ns)) continue;
      const std::size_t between = side == 0 ? k - 1 : k;
      const std::size_t m = (st[between] + st[between + 1]) / 2;
      if (m == i) continue;
      const std::vector<double>& half = halfway[between];
      for (int j = 0; j < N; ++j) {
        const double v = half[std::size_t(j)];
        if (std::isnan(v) || std::isnan(rho[k][std::size_t(j)])) continue;
        // The half-way plane's contour point, seen from this station's centre along its ray.
        const double a = 2 * kPi * j / N;
        const Vector3d x = pts[m] + v * (std::cos(a) * f.normal[m] + std::sin(a) * f.binormal[m]) - pts[i];
        const Vector2d q(x.dot(f.normal[i]), x.dot(f.binormal[i]));
        rho[k][std::size_t(j)] = std::max(rho[k][std::size_t(j)], q.norm());
      }
    }
    for (double v : rho[k]) {
      if (std::isnan(v)) ++missing;
      else if (v > o.flare_ratio * ref_at(i)) ++flared;
    }
  }
  // Missing rays: from the neighbouring rays of the station, or, where most
  // of a station is missing (an open end cut obliquely, an ostium), from the
  // nearest stations along the centerline with the same ray.
  std::vector<char> filled(ns, 0);
  for (std::size_t k = 0; k < ns; ++k) filled[k] = fill_around(rho[k]) ? 1 : 0;
  for (std::size_t k = 0; k < ns; ++k) {
    if (filled[k]) continue;
    for (int j = 0; j < N; ++j) {
      if (!std::isnan(rho[k][std::size_t(j)])) continue;
      long a = long(k) - 1, b = long(k) + 1;
      while (a >= 0 && !filled[std::size_t(a)]) --a;
      while (b < long(ns) && !filled[std::size_t(b)]) ++b;
      const double ra = a >= 0 ? rho[std::size_t(a)][std::size_t(j)] : NAN, rb = b < long(ns) ? rho[std::size_t(b)][std::size_t(j)] : NAN;
      double v = std::isnan(ra) ? rb : std::isnan(rb) ? ra : ra + (rb - ra) * double(long(k) - a) / double(b - a);
      rho[k][std::size_t(j)] = std::isnan(v) ? ref_at(st[k]) : v;
    }
  }

  // 2. The healthy reference contour: the lumen's contour united with the
  // reference circle of radius R* = r_ref + m (r_ref - r)₊ about the
  // centerline (m: remodeling; r the inscribed radius). The reference line is
  // fitted to the inscribed radius, so a healthy or oval lumen (every ray at
  // least its inscribed radius) keeps its own shape, while a stenosed one,
  // concentric or eccentric, is widened to the reference size and no more
  // (the plaque fills the space between). Outside the rule's analysed range
  // (the excluded ends) the lumen is its own reference. R* is averaged over
  // ±1 mm so the wall does not step where a lesion begins.
  std::vector<std::vector<double>> rstar(ns, std::vector<double>(1, 0.0));
  for (std::size_t k = 0; k < ns; ++k) {
    const std::size_t i = st[k];
    const double ref = ref_at(i);
    const bool inside = S[i] >= prof.lo && S[i] <= prof.hi;
    rstar[k][0] = inside ? ref + o.remodeling * std::max(0.0, ref - r[i]) : r[i];
  }
  rstar = smooth_along(rstar, std::max(1, int(std::round(1.0 / h))));
  std::vector<std::vector<double>> reference(ns);
  for (std::size_t k = 0; k < ns; ++k) {
    reference[k] = rho[k];
    for (double& v : reference[k]) v = std::max(v, rstar[k][0]);
  }

  // 3. Dilation by t(s), smoothed along s over ±0.5 mm, never closer to the
  // lumen than 3/4 t.
  std::vector<std::vector<double>> W(ns);
  for (std::size_t k = 0; k < ns; ++k) W[k] = dilate(reference[k], thickness_at(st[k]), 4);
  W = smooth_along(W, std::max(1, int(std::round(0.5 / h))));
  double tmin = std::numeric_limits<double>::infinity(), tmax = 0;
  for (std::size_t k = 0; k < ns; ++k) {
    const double t = thickness_at(st[k]);
    for (int j = 0; j < N; ++j) {
      double& w = W[k][std::size_t(j)];
      w = std::max(w, rho[k][std::size_t(j)] + 0.75 * t);
      // The wall proper: beyond the reference contour (the plaque is inside it).
      tmin = std::min(tmin, w - reference[k][std::size_t(j)]);
      tmax = std::max(tmax, w - reference[k][std::size_t(j)]);
    }
  }

  TriSurface wall;
  for (std::size_t k = 0; k < ns; ++k) {
    const std::size_t i = st[k];
    for (int j = 0; j < N; ++j) {
      const double a = 2 * kPi * j / N;
      wall.points.push_back(pts[i] + W[k][std::size_t(j)] * (std::cos(a) * f.normal[i] + std::sin(a) * f.binormal[i]));
    }
  }
  for (std::size_t k = 0; k + 1 < ns; ++k)
    for (int j = 0; j < N; ++j) {
      const int a = int(k) * N + j, b = int(k) * N + (j + 1) % N, c = int(k + 1) * N + j, d = int(k + 1) * N + (j + 1) % N;
      wall.triangles.push_back({a, b, d});
      wall.triangles.push_back({a, d, c});
    }

  // 4. Check the surfaces as built, between the stations too: on planes
  // halfway between stations the wall's cut encloses the lumen's with at
  // least half the local thickness on every ray that meets both.
  const MeshData wall_mesh = mesh_from_surface(wall);
  double worst = std::numeric_limits<double>::infinity();
  Vector3d where = pts[0];
  double where_s = 0, where_t = 0;
  for (std::size_t k = 0; k + 1 < ns; ++k) {
    const std::size_t i = (st[k] + st[k + 1]) / 2;
    const auto lc = plane_cut(lumen_mesh, pts[i], f.tangent[i], f.normal[i], f.binormal[i]);
    const auto wc = plane_cut(wall_mesh, pts[i], f.tangent[i], f.normal[i], f.binormal[i]);
    const double t = thickness_at(i);
    for (int j = 0; j < N; ++j) {
      const double a = 2 * kPi * (j + 0.5) / N;
      const Vector2d d(std::cos(a), std::sin(a));
      const double rl = ray_hit(lc, d), rw = ray_hit(wc, d);
      if (std::isnan(rl) || std::isnan(rw) || rl > 3 * ref_at(i)) continue;
      if ((rw - rl) / t < worst) {
        worst = (rw - rl) / t, where_s = S[i], where_t = t;
        where = pts[i] + rl * (d.x() * f.normal[i] + d.y() * f.binormal[i]);
      }
    }
  }
  summary.set("wall_thickness_min", tmin, "mm");
  summary.set("wall_thickness_max", tmax, "mm");
  summary.set("wall_thickness_reference", thickness_at(st[ns / 2]), "mm");
  summary.set("wall_missing_ray_fraction", double(missing) / double(ns * std::size_t(N)));
  summary.set("wall_flared_ray_fraction", double(flared) / double(ns * std::size_t(N)));
  summary.set("wall_min_clearance_ratio", worst);
  summary.note("wall_thickness_rule",
               o.wall_thickness ? fmt::format("fixed: {} mm (wall_thickness)", *o.wall_thickness)
                                : fmt::format("t = (t_I + 0.2146 D_ref) / 0.5708, t_I = {} mm (nominal_intima), D_ref the "
                                              "healthy reference diameter of the stenosis rule (DESIGN.md §8)",
                                              o.nominal_intima));
  log::info("wall: synthesized from the lumen, {} sections, thickness {:.3f} to {:.3f} mm, {:.1f} % of the rays missed "
            "the lumen (filled in), {:.1f} % flared beyond {} r_ref",
            ns, tmin, tmax, 100.0 * double(missing) / double(ns * std::size_t(N)),
            100.0 * double(flared) / double(ns * std::size_t(N)), o.flare_ratio);
  if (worst < 0.5)
    throw InputError(fmt::format(
        "wall (synthesized from the lumen): only {:.3f} mm outside the lumen at s = {:.2f} mm near ({:.3f}, {:.3f}, "
        "{:.3f}), below half the wall thickness {:.3f} mm; the lumen bends or branches too sharply there for sections "
        "normal to its centerline: {}",
        worst * where_t, where_s, where.x(), where.y(), where.z(), where_t, o.remedy));
  return wall;
}

}  // namespace stentsim::segmentation
