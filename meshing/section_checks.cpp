// Geometric checks of the wall sections before they are lofted (DESIGN.md §5):
// the OCC lofts through sections that overlap, or through interface contours
// that cross, self-intersect; gmsh then fails with an obscure message or gives
// inverted elements. Both conditions are caught here and reported with the
// section, its arc length and position, and what to change.
#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"
#include "meshing/patient_mesh.hpp"

namespace stentsim::meshing {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

/// The closed curve OCC lofts through a section's contour: gmsh's addSpline
/// with equal first and last point is GeomAPI_Interpolate, the periodic C2
/// cubic interpolant with chord-length parameters. Sampled `per_span` times
/// per span, in the section's (normal, binormal) coordinates.
std::vector<Vector2d> periodic_spline_samples(const std::vector<Vector2d>& p, int per_span) {
  const int n = int(p.size());
  std::vector<double> h(std::size_t(n), 0.0);
  for (int i = 0; i < n; ++i) h[std::size_t(i)] = std::max(1e-14, (p[std::size_t((i + 1) % n)] - p[std::size_t(i)]).norm());
  // Second derivatives M_i: h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1}
  //   = 6 ((P_{i+1} - P_i) / h_i - (P_i - P_{i-1}) / h_{i-1}), cyclic.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n), rhs(n, 2);
  for (int i = 0; i < n; ++i) {
    const int im = (i + n - 1) % n, ip = (i + 1) % n;
    const double hm = h[std::size_t(im)], hi = h[std::size_t(i)];
    a(i, im) += hm;
    a(i, i) += 2 * (hm + hi);
    a(i, ip) += hi;
    rhs.row(i) = 6 * ((p[std::size_t(ip)] - p[std::size_t(i)]) / hi - (p[std::size_t(i)] - p[std::size_t(im)]) / hm).transpose();
  }
  const Eigen::MatrixXd m = a.partialPivLu().solve(rhs);
  std::vector<Vector2d> out;
  out.reserve(std::size_t(n * per_span));
  for (int i = 0; i < n; ++i) {
    const int ip = (i + 1) % n;
    const double hi = h[std::size_t(i)];
    const Vector2d mi = m.row(i).transpose(), mj = m.row(ip).transpose();
    for (int j = 0; j < per_span; ++j) {
      const double t = hi * j / per_span, u = hi - t;
      out.push_back((u * u * u * mi + t * t * t * mj) / (6 * hi) + (p[std::size_t(i)] / hi - mi * hi / 6) * u +
                    (p[std::size_t(ip)] / hi - mj * hi / 6) * t);
    }
  }
  return out;
}

double cross2(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Winding number of the closed polygon `poly` around `x` (0: outside).
int winding(const std::vector<Vector2d>& poly, const Vector2d& x) {
  int wn = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vector2d& a = poly[i];
    const Vector2d& b = poly[(i + 1) % poly.size()];
    if (a.y() <= x.y()) {
      if (b.y() > x.y() && cross2(b - a, x - a) > 0) ++wn;
    } else if (b.y() <= x.y() && cross2(b - a, x - a) < 0) {
      --wn;
    }
  }
  return wn;
}

std::string surface_name(const WallSections& w, std::size_t k) {
  if (k == 0) return "lumen (endothelium)";
  if (k + 1 == w.radius[0].size()) return "outer wall";
  return fmt::format("{}/{} interface", tags::layer_name(w.layers[k - 1]), tags::layer_name(w.layers[k]));
}

}  // namespace

double check_wall_sections(const WallSections& w, double min_gap_ratio) {
  const std::size_t ns = w.origin.size();
  if (ns < 2 || w.radius.size() != ns) throw InputError("mesh: wall sections: fewer than two sections");
  const std::size_t nk = w.radius[0].size();
  if (nk < 2 || w.layers.size() != nk - 1) throw InputError("mesh: wall sections: layers and surfaces do not match");
  constexpr int kPerSpan = 8;
  // Sampled splines of every section and surface, 2D in the section's frame.
  std::vector<std::vector<std::vector<Vector2d>>> curve(ns);
  for (std::size_t s = 0; s < ns; ++s) {
    const std::size_t nr = w.radius[s][0].size();
    for (std::size_t k = 0; k < nk; ++k) {
      if (w.radius[s][k].size() != nr) throw InputError(fmt::format("mesh: wall section {}: surfaces with different ray counts", s));
      std::vector<Vector2d> p(nr);
      for (std::size_t i = 0; i < nr; ++i) {
        const double th = 2 * std::numbers::pi * double(i) / double(nr);
        p[i] = w.radius[s][k][i] * Vector2d(std::cos(th), std::sin(th));
      }
      curve[s].push_back(periodic_spline_samples(p, kPerSpan));
    }
  }
  auto at3 = [&](std::size_t s, const Vector2d& q) { return Vector3d(w.origin[s] + q.x() * w.normal[s] + q.y() * w.binormal[s]); };

  // 1. Nested contours in every section: each contour's spline turns once
  // around the centerline point (star-shaped, so simple), and every sample of
  // the inner one lies inside the next one outward (no crossing).
  for (std::size_t s = 0; s < ns; ++s) {
    for (std::size_t k = 0; k < nk; ++k) {
      const auto& c = curve[s][k];
      for (std::size_t j = 0; j < c.size(); ++j)
        if (cross2(c[j], c[(j + 1) % c.size()]) <= 0) {
          const Vector3d x = at3(s, c[j]);
          throw InputError(fmt::format(
              "mesh: section {} (s = {:.2f} mm along the centerline): the {} contour folds back near ({:.3f}, {:.3f}, "
              "{:.3f}) (its spline is not star-shaped around the centerline); smooth the surfaces there, raise "
              "mesh.points_per_section or choose a smaller ROI",
              s, w.abscissa[s], surface_name(w, k), x.x(), x.y(), x.z()));
        }
    }
    for (std::size_t k = 0; k + 1 < nk; ++k)
      for (const Vector2d& q : curve[s][k])
        if (winding(curve[s][k + 1], q) == 0) {
          const Vector3d x = at3(s, q);
          throw InputError(fmt::format(
              "mesh: section {} (s = {:.2f} mm along the centerline): the {} crosses the {} near ({:.3f}, {:.3f}, "
              "{:.3f}); the {} is too thin there for the lofted contours: raise mesh.min_intima, smooth the wall or "
              "raise mesh.points_per_section",
              s, w.abscissa[s], surface_name(w, k), surface_name(w, k + 1), x.x(), x.y(), x.z(),
              tags::layer_name(w.layers[k])));
        }
  }

  // 2. Consecutive sections do not meet inside the wall: the outer contour of
  // section s+1 lies ahead of section s's plane by at least min_gap_ratio of
  // their spacing, and that of s behind the plane of s+1. The planes of two
  // sections meet on a line; on a bend of radius R (centerline) that line is R
  // from the centerline, so an outer radius r >= R puts it inside the wall (a
  // straight tube has gap = spacing; the bend's inner side has (1 - r/R) of it).
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s + 1 < ns; ++s) {
    const double ds = (w.origin[s + 1] - w.origin[s]).norm();
    const double need = min_gap_ratio * ds;
    double worst = std::numeric_limits<double>::infinity();
    Vector3d where = w.origin[s];
    std::size_t which = s;
    for (const Vector2d& q : curve[s + 1][nk - 1]) {
      const Vector3d x = at3(s + 1, q);
      const double d = (x - w.origin[s]).dot(w.tangent[s]);
      if (d < worst) worst = d, where = x, which = s + 1;
    }
    for (const Vector2d& q : curve[s][nk - 1]) {
      const Vector3d x = at3(s, q);
      const double d = (w.origin[s + 1] - x).dot(w.tangent[s + 1]);
      if (d < worst) worst = d, where = x, which = s;
    }
    smallest = std::min(smallest, worst / ds);
    if (worst < need) {
      // Local bend radius of the centerline from the turn of the tangent.
      const double turn = std::acos(std::clamp(w.tangent[s].dot(w.tangent[s + 1]), -1.0, 1.0));
      const double bend = turn > 1e-12 ? ds / turn : std::numeric_limits<double>::infinity();
      double rmax = 0;
      for (double r : w.radius[which][nk - 1]) rmax = std::max(rmax, r);
      throw InputError(fmt::format(
          "mesh: sections {} and {} (s = {:.2f} and {:.2f} mm along the centerline) {} inside the wall near "
          "({:.3f}, {:.3f}, {:.3f}): the outer wall of section {} is {:.3f} mm from the other section's plane, "
          "below {:.3f} mm ({} of the {:.3f} mm spacing); the centerline bends with radius ~{:.2f} mm there "
          "against an outer radius up to {:.2f} mm. Smooth the centerline, raise mesh.station_spacing (a longer "
          "tangent window) or choose a smaller ROI that leaves the bend out",
          s, s + 1, w.abscissa[s], w.abscissa[s + 1], worst <= 0 ? "overlap" : "come too close", where.x(), where.y(), where.z(), which, worst, need,
          min_gap_ratio, ds, bend, rmax));
    }
  }
  return smallest;
}

}  // namespace stentsim::meshing
