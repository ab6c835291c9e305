#include "solver/app/qoi/ring_geometry.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>

namespace stentsim::solver {

std::vector<RingMeasure> measure_rings(const std::vector<std::vector<Eigen::Vector3d>>& ring_points,
                                       const Eigen::Vector3d& single_ring_axis) {
  const std::size_t n = ring_points.size();
  std::vector<RingMeasure> rings(n);
  for (std::size_t k = 0; k < n; ++k) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto& p : ring_points[k]) c += p;
    rings[k].centroid = c / static_cast<double>(std::max<std::size_t>(1, ring_points[k].size()));
  }
  for (std::size_t k = 0; k < n; ++k) {
    Eigen::Vector3d t = single_ring_axis;
    if (n >= 2) t = rings[std::min(k + 1, n - 1)].centroid - rings[k == 0 ? 0 : k - 1].centroid;
    rings[k].axis = t.normalized();
    double acc = 0.0;
    for (const auto& p : ring_points[k]) {
      const Eigen::Vector3d d = p - rings[k].centroid;
      acc += (d - d.dot(rings[k].axis) * rings[k].axis).norm();
    }
    rings[k].diameter = 2.0 * acc / static_cast<double>(std::max<std::size_t>(1, ring_points[k].size()));
  }
  return rings;
}

Eigen::Vector3d axis_normal_to(const std::vector<Eigen::Vector3d>& radial_directions) {
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (const auto& e : radial_directions) S += e * e.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(S);
  return eig.eigenvectors().col(0).normalized();  // eigenvalues ascending
}

double max_centroid_curvature(const std::vector<RingMeasure>& rings) {
  double kappa = 0.0;
  for (std::size_t k = 1; k + 1 < rings.size(); ++k) {
    const Eigen::Vector3d a = rings[k].centroid - rings[k - 1].centroid, b = rings[k + 1].centroid - rings[k].centroid,
                          c = rings[k + 1].centroid - rings[k - 1].centroid;
    const double den = a.norm() * b.norm() * c.norm();
    if (den > 0) kappa = std::max(kappa, 2.0 * a.cross(b).norm() / den);  // 4·area = 2‖a × b‖
  }
  return kappa;
}

Dogboning dogboning(const std::vector<double>& d) {
  Dogboning out;
  const std::size_t n = d.size();
  if (n < 2) return out;
  const double distal = 0.5 * (d.front() + d.back());
  const double central = n % 2 ? d[n / 2] : 0.5 * (d[n / 2 - 1] + d[n / 2]);
  if (distal > 0) out.distal = 100.0 * (distal - central) / distal;
  if (central > 0) out.central = 100.0 * (distal - central) / central;
  return out;
}

}  // namespace stentsim::solver
