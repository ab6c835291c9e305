#include "device_gen/device_axis.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace stentsim::device_gen {
namespace {

// 10-point Gauss-Legendre on [-1, 1].
constexpr double kGaussX[5] = {0.1488743389816312, 0.4333953941292472, 0.6794095682990244, 0.8650633666889845,
                               0.9739065285171717};
constexpr double kGaussW[5] = {0.2955242247147529, 0.2692667193099963, 0.2190863625159820, 0.1494513491505806,
                               0.0666713443086881};
constexpr int kSubdivisions = 16;   // per knot span, for the arc-length table
constexpr double kFrameStep = 0.01;  // mm, rotation-minimizing frame grid

template <typename F>
double gauss(F f, double a, double b) {
  const double h = 0.5 * (b - a), m = 0.5 * (a + b);
  double sum = 0;
  for (int i = 0; i < 5; ++i) sum += kGaussW[i] * (f(m - h * kGaussX[i]) + f(m + h * kGaussX[i]));
  return h * sum;
}

Eigen::Vector3d any_normal_to(const Eigen::Vector3d& t) {
  Eigen::Index i;
  t.cwiseAbs().minCoeff(&i);
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  e(i) = 1.0;
  return (e - e.dot(t) * t).normalized();
}

}  // namespace

Eigen::Vector3d double_reflection(const Eigen::Vector3d& x0, const Eigen::Vector3d& t0, const Eigen::Vector3d& r0,
                                  const Eigen::Vector3d& x1, const Eigen::Vector3d& t1) {
  // Reflect in the bisector plane of x0, x1, then in the plane that maps the
  // reflected tangent onto t1 (Wang et al. 2008, Algorithm "double reflection").
  const Eigen::Vector3d v1 = x1 - x0;
  const double c1 = v1.squaredNorm();
  Eigen::Vector3d rL = r0, tL = t0;
  if (c1 > 1e-300) {
    rL = r0 - (2.0 / c1) * v1.dot(r0) * v1;
    tL = t0 - (2.0 / c1) * v1.dot(t0) * v1;
  }
  const Eigen::Vector3d v2 = t1 - tL;
  const double c2 = v2.squaredNorm();
  Eigen::Vector3d r1 = c2 > 1e-300 ? Eigen::Vector3d(rL - (2.0 / c2) * v2.dot(rL) * v2) : rL;
  // Remove round-off drift: keep r1 a unit vector normal to t1.
  r1 -= r1.dot(t1) * t1;
  return r1.normalized();
}

DeviceAxis DeviceAxis::straight(double length) {
  DeviceAxis a;
  a.length_ = length;
  return a;
}

DeviceAxis DeviceAxis::along(const SplineCurve& curve, double u_mid, double length, const Eigen::Vector3d& initial_normal) {
  DeviceAxis a;
  a.length_ = length;
  a.curve_ = curve;
  // Arc-length table over the knot spans of the x spline (all three share knots).
  const auto& t = curve.x.knots;
  std::vector<double> breaks;
  for (double k : t)
    if (k >= curve.begin() && k <= curve.end() && (breaks.empty() || k > breaks.back())) breaks.push_back(k);
  a.table_u_.push_back(breaks.front());
  a.table_s_.push_back(0.0);
  auto speed = [&](double u) { return curve.derivative(u, 1).norm(); };
  for (std::size_t i = 0; i + 1 < breaks.size(); ++i) {
    for (int j = 1; j <= kSubdivisions; ++j) {
      const double u0 = a.table_u_.back();
      const double u1 = breaks[i] + (breaks[i + 1] - breaks[i]) * j / kSubdivisions;
      a.table_s_.push_back(a.table_s_.back() + gauss(speed, u0, u1));
      a.table_u_.push_back(u1);
    }
  }
  a.offset_ = a.curve_arc_length(u_mid) - 0.5 * length;
  a.build_frames(initial_normal);
  return a;
}

double DeviceAxis::curve_arc_length(double u) const {
  if (!curve_) return u;
  u = std::clamp(u, table_u_.front(), table_u_.back());
  auto it = std::upper_bound(table_u_.begin(), table_u_.end(), u);
  const std::size_t i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - table_u_.begin() - 1, 0));
  if (i + 1 >= table_u_.size()) return table_s_.back();
  const auto& c = *curve_;
  return table_s_[i] + gauss([&](double v) { return c.derivative(v, 1).norm(); }, table_u_[i], u);
}

double DeviceAxis::curve_parameter(double s) const {
  if (!curve_) return s;
  if (s <= 0) return table_u_.front();
  if (s >= table_s_.back()) return table_u_.back();
  auto it = std::upper_bound(table_s_.begin(), table_s_.end(), s);
  const std::size_t i = static_cast<std::size_t>(it - table_s_.begin() - 1);
  double lo = table_u_[i], hi = table_u_[i + 1];
  // Newton on s(u) - s with a bisection safeguard; s(u) is smooth in the sub-interval.
  double u = lo + (hi - lo) * (s - table_s_[i]) / (table_s_[i + 1] - table_s_[i]);
  for (int it2 = 0; it2 < 60; ++it2) {
    const double f = curve_arc_length(u) - s;
    if (std::abs(f) < 1e-15 * std::max(1.0, table_s_.back())) break;
    (f > 0 ? hi : lo) = u;
    double next = u - f / curve_->derivative(u, 1).norm();
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    u = next;
  }
  return u;
}

DeviceAxis::Point DeviceAxis::point(double sigma) const {
  if (!curve_) return {Eigen::Vector3d(0, 0, sigma - 0.5 * length_), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero()};
  const double s = sigma + offset_;
  const double total = table_s_.back();
  const auto& c = *curve_;
  auto at = [&](double u) {
    const Eigen::Vector3d d1 = c.derivative(u, 1), d2 = c.derivative(u, 2);
    const double v = d1.norm();
    const Eigen::Vector3d t = d1 / v;
    return Point{c.position(u), t, (d2 - d2.dot(t) * t) / (v * v)};
  };
  if (s < 0) {
    Point p = at(table_u_.front());
    p.position += s * p.tangent;
    p.curvature.setZero();
    return p;
  }
  if (s > total) {
    Point p = at(table_u_.back());
    p.position += (s - total) * p.tangent;
    p.curvature.setZero();
    return p;
  }
  return at(curve_parameter(s));
}

Eigen::Vector3d DeviceAxis::position(double sigma) const { return point(sigma).position; }

void DeviceAxis::build_frames(const Eigen::Vector3d& initial_normal) {
  const int n = std::max(1, static_cast<int>(std::ceil(length_ / kFrameStep)));
  grid_step_ = length_ / n;
  grid_normal_.resize(static_cast<std::size_t>(n) + 1);
  Point p = point(0.0);
  Eigen::Vector3d r = initial_normal - initial_normal.dot(p.tangent) * p.tangent;
  r = r.norm() > 1e-8 ? Eigen::Vector3d(r.normalized()) : any_normal_to(p.tangent);
  grid_normal_[0] = r;
  for (int i = 1; i <= n; ++i) {
    const Point q = point(i * grid_step_);
    r = double_reflection(p.position, p.tangent, r, q.position, q.tangent);
    grid_normal_[static_cast<std::size_t>(i)] = r;
    p = q;
  }
}

AxisFrame DeviceAxis::frame(double sigma) const {
  const Point p = point(sigma);
  AxisFrame f;
  f.position = p.position;
  f.tangent = p.tangent;
  f.curvature = p.curvature;
  if (!curve_) {
    f.normal = Eigen::Vector3d::UnitX();
  } else {
    const double g = std::clamp(sigma, 0.0, length_) / grid_step_;
    std::size_t i = static_cast<std::size_t>(std::floor(g));
    i = std::min(i, grid_normal_.size() - 1);
    const Point q = point(static_cast<double>(i) * grid_step_);
    f.normal = double_reflection(q.position, q.tangent, grid_normal_[i], p.position, p.tangent);
  }
  f.binormal = f.tangent.cross(f.normal);
  return f;
}

double DeviceAxis::max_curvature() const {
  if (!curve_) return 0.0;
  double k = 0;
  for (std::size_t i = 0; i < grid_normal_.size(); ++i) k = std::max(k, point(static_cast<double>(i) * grid_step_).curvature.norm());
  return k;
}

}  // namespace stentsim::device_gen
