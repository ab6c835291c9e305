#pragma once
// Synthetic curves for the device tests: sampled by arc length at 0.1 mm and
// turned into a SplineCurve by the smoothing spline with a tiny s (close to
// interpolation), as the placement stage would.
#include <Eigen/Core>

#include <cmath>
#include <functional>
#include <vector>

#include "device_gen/fitpack/curfit.hpp"
#include "device_gen/spline_curve.hpp"

namespace stentsim::device_gen::synthetic {

/// A curve given by arc length s in [0, length].
using Curve = std::function<Eigen::Vector3d(double)>;

/// Planar arc of radius R in the xy plane starting at the origin along +x.
inline Curve planar_arc(double R) {
  return [R](double s) { return Eigen::Vector3d(R * std::sin(s / R), R * (1 - std::cos(s / R)), 0.0); };
}

/// Helix of radius a and pitch parameter b (z = b * theta), by arc length.
inline Curve helix(double a, double b) {
  const double c = std::sqrt(a * a + b * b);
  return [a, b, c](double s) {
    const double th = s / c;
    return Eigen::Vector3d(a * std::cos(th) - a, a * std::sin(th), b * th);
  };
}

inline SplineCurve fit_curve(const Curve& f, double length, double spacing = 0.1, double s = 1e-10) {
  const int n = static_cast<int>(std::lround(length / spacing));
  std::vector<double> u, x, y, z, w;
  for (int i = 0; i <= n; ++i) {
    const double si = length * i / n;
    const Eigen::Vector3d p = f(si);
    u.push_back(si);
    x.push_back(p.x());
    y.push_back(p.y());
    z.push_back(p.z());
    w.push_back(1.0);
  }
  SplineCurve c;
  c.x = fitpack::univariate_spline(u, x, w, s).spline;
  c.y = fitpack::univariate_spline(u, y, w, s).spline;
  c.z = fitpack::univariate_spline(u, z, w, s).spline;
  return c;
}

}  // namespace stentsim::device_gen::synthetic
