#include "segmentation_io/polyline_frames.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace stentsim::segmentation {

using Eigen::Vector3d;

std::vector<Vector3d> polyline_tangents(const std::vector<Vector3d>& p) {
  const std::size_t n = p.size();
  std::vector<Vector3d> t(n, Vector3d::UnitZ());
  if (n < 2) return t;
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t a = i == 0 ? 0 : i - 1, b = i + 1 == n ? n - 1 : i + 1;
    Vector3d d = p[b] - p[a];
    if (d.norm() > 0) t[i] = d.normalized();
    else if (i > 0) t[i] = t[i - 1];
  }
  return t;
}

Frames parallel_transport_frames(const std::vector<Vector3d>& p, std::optional<Vector3d> first_normal) {
  Frames f;
  f.tangent = polyline_tangents(p);
  const std::size_t n = p.size();
  f.normal.resize(n);
  f.binormal.resize(n);
  if (n == 0) return f;
  const Vector3d& t0 = f.tangent[0];
  Vector3d r0;
  if (first_normal && (*first_normal - first_normal->dot(t0) * t0).norm() > 1e-9) {
    r0 = (*first_normal - first_normal->dot(t0) * t0).normalized();
  } else {
    // A fixed choice: the coordinate axis least aligned with the tangent.
    Eigen::Index k;
    t0.cwiseAbs().minCoeff(&k);
    Vector3d e = Vector3d::Unit(k);
    r0 = (e - e.dot(t0) * t0).normalized();
  }
  f.normal[0] = r0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    // Double reflection (Wang et al. 2008, Algorithm "RMF by double reflection").
    Vector3d v1 = p[i + 1] - p[i];
    double c1 = v1.dot(v1);
    Vector3d rL = f.normal[i], tL = f.tangent[i];
    if (c1 > 0) {
      rL = f.normal[i] - (2 / c1) * v1.dot(f.normal[i]) * v1;
      tL = f.tangent[i] - (2 / c1) * v1.dot(f.tangent[i]) * v1;
    }
    Vector3d v2 = f.tangent[i + 1] - tL;
    double c2 = v2.dot(v2);
    Vector3d r = c2 > 0 ? Vector3d(rL - (2 / c2) * v2.dot(rL) * v2) : rL;
    // Re-orthonormalize against round-off.
    r = (r - r.dot(f.tangent[i + 1]) * f.tangent[i + 1]).normalized();
    f.normal[i + 1] = r;
  }
  for (std::size_t i = 0; i < n; ++i) f.binormal[i] = f.tangent[i].cross(f.normal[i]);
  return f;
}

std::vector<double> cumulative_length(const std::vector<Vector3d>& p) {
  std::vector<double> s(p.size(), 0.0);
  for (std::size_t i = 1; i < p.size(); ++i) s[i] = s[i - 1] + (p[i] - p[i - 1]).norm();
  return s;
}

std::vector<Vector3d> resample_polyline(const std::vector<Vector3d>& p, double spacing) {
  if (p.size() < 2) return p;
  auto s = cumulative_length(p);
  const double L = s.back();
  const int n = std::max(1, int(std::round(L / spacing)));
  std::vector<Vector3d> out;
  out.reserve(n + 1);
  std::size_t j = 0;
  for (int k = 0; k <= n; ++k) {
    double target = L * k / n;
    while (j + 2 < p.size() && s[j + 1] < target) ++j;
    double seg = s[j + 1] - s[j];
    double w = seg > 0 ? std::clamp((target - s[j]) / seg, 0.0, 1.0) : 0.0;
    out.push_back((1 - w) * p[j] + w * p[j + 1]);
  }
  return out;
}

double smooth_with_bounded_displacement(std::vector<Eigen::Vector3d>& pts, const std::vector<double>& bound,
                                        double samples) {
  if (pts.size() < 3) return 0;
  // Taubin's lambda|mu filter (Taubin 1995, "A signal processing approach to
  // fair surface design"): a Laplacian step of lambda, then one of mu < 0.
  // Its pass band ends at k_PB = 1/lambda + 1/mu (k = 1 - cos w for a
  // frequency of w per sample), here a wavelength of 4 `samples` samples:
  // kinks (broadband) are smoothed, arcs (low frequency) keep their radius,
  // which plain Laplacian steps would shrink.
  const double lambda = 0.5, kpb = 1 - std::cos(std::numbers::pi / std::max(1.0, 8 * samples));
  const double mu = 1 / (kpb - 1 / lambda);
  const std::vector<Eigen::Vector3d> raw = pts;
  const int steps = std::max(1, int(std::lround(8 * samples * samples)));
  std::vector<Eigen::Vector3d> next = pts;
  for (int it = 0; it < 2 * steps; ++it) {
    const double f = it % 2 == 0 ? lambda : mu;
    for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
      next[i] = pts[i] + f * (0.5 * (pts[i - 1] + pts[i + 1]) - pts[i]);
      const Eigen::Vector3d d = next[i] - raw[i];
      if (d.norm() > bound[i]) next[i] = raw[i] + d * (bound[i] / d.norm());
    }
    std::swap(pts, next);
  }
  double moved = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) moved = std::max(moved, (pts[i] - raw[i]).norm());
  return moved;
}

}  // namespace stentsim::segmentation
