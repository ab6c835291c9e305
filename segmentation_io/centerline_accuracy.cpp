// Accuracy of a centerline against a known true one (phantoms).
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "common/error.hpp"
#include "segmentation_io/centerline.hpp"

namespace stentsim::segmentation {

using Eigen::Vector3d;

namespace {

const std::vector<double>& array_of(const MeshData& m, const char* name, const char* what) {
  auto it = m.point_data.find(name);
  if (it == m.point_data.end() || it->second.values.size() != m.points.size())
    throw InputError(fmt::format("{} centerline: point array '{}' is missing", what, name));
  return it->second.values;
}

// Closest point of the polyline to x: segment index and fraction.
std::pair<std::size_t, double> project(const std::vector<Vector3d>& p, const Vector3d& x) {
  double best = std::numeric_limits<double>::infinity();
  std::pair<std::size_t, double> at{0, 0};
  for (std::size_t i = 0; i + 1 < p.size(); ++i) {
    Vector3d d = p[i + 1] - p[i];
    double w = d.squaredNorm() > 0 ? std::clamp((x - p[i]).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
    double e = (p[i] + w * d - x).squaredNorm();
    if (e < best) best = e, at = {i, w};
  }
  return at;
}

std::size_t argmin(const std::vector<double>& v) { return std::size_t(std::min_element(v.begin(), v.end()) - v.begin()); }

}  // namespace

CenterlineAccuracy compare_with_true_centerline(const MeshData& computed, const MeshData& truth,
                                                double end_exclusion_radii) {
  const auto& R = array_of(computed, "MaximumInscribedSphereRadius", "computed");
  const auto& Rt = array_of(truth, "MaximumInscribedSphereRadius", "true");
  const auto& At = array_of(truth, "Abscissas", "true");
  const auto& pt = truth.points;
  if (pt.size() < 2 || computed.points.empty()) throw InputError("centerline accuracy: empty centerline");
  CenterlineAccuracy acc;
  for (std::size_t i = 0; i < computed.points.size(); ++i) {
    auto [k, w] = project(pt, computed.points[i]);
    double a = (1 - w) * At[k] + w * At[k + 1];
    double rt = (1 - w) * Rt[k] + w * Rt[k + 1];
    if (a < end_exclusion_radii * Rt.front() || a > At.back() - end_exclusion_radii * Rt.back()) continue;
    Vector3d q = pt[k] + w * (pt[k + 1] - pt[k]);
    acc.centerline_distance_max = std::max(acc.centerline_distance_max, (computed.points[i] - q).norm() / rt);
    acc.inscribed_radius_error_max = std::max(acc.inscribed_radius_error_max, std::abs(R[i] - rt) / rt);
    ++acc.points_compared;
  }
  // Narrowest sites (computed: sub-sample parabola as in compute_centerline is
  // not needed at the 0.5 mm tolerance; the sample is within spacing/2).
  std::size_t ic = argmin(R), it = argmin(Rt);
  // A healthy phantom has no narrowest site: compare only when the truth has
  // one (radius 1 % below its largest); otherwise the error stays absent.
  double rmax = *std::max_element(Rt.begin(), Rt.end());
  if (Rt[it] < 0.99 * rmax) acc.stenosis_site_error = (computed.points[ic] - pt[it]).norm();
  return acc;
}

}  // namespace stentsim::segmentation
