#include "device_gen/surface_distance.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/error.hpp"
#include "common/triangle_distance.hpp"

namespace stentsim::device_gen {

SurfaceDistance::SurfaceDistance(const MeshData& s) : pts_(s.points) {
  for (std::size_t c = 0; c < s.num_cells(); ++c) {
    const auto n = s.cell(c);
    auto id = [&](std::size_t i) { return static_cast<std::size_t>(n[i]); };
    if (s.cell_types[c] == CellType::triangle) tris_.push_back({id(0), id(1), id(2)});
    if (s.cell_types[c] == CellType::quad) {
      tris_.push_back({id(0), id(1), id(2)});
      tris_.push_back({id(0), id(2), id(3)});
    }
  }
  if (tris_.empty()) throw InputError("lumen surface: no triangles");
  double edge = 0;
  lo_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo_;
  for (const auto& t : tris_) {
    const Eigen::Vector3d &a = pts_[t[0]], &b = pts_[t[1]], &c = pts_[t[2]];
    normals_.push_back((b - a).cross(c - a).normalized());
    edge += (b - a).norm() + (c - b).norm() + (a - c).norm();
    lo_ = lo_.cwiseMin(a).cwiseMin(b).cwiseMin(c);
    hi = hi.cwiseMax(a).cwiseMax(b).cwiseMax(c);
  }
  edge /= 3.0 * static_cast<double>(tris_.size());
  const Eigen::Vector3d ext = hi - lo_;
  h_ = std::max({2.0 * edge, std::cbrt(std::max(ext.prod(), 1e-30) / 2e6), 1e-9});
  for (int i = 0; i < 3; ++i) dims_[static_cast<std::size_t>(i)] = std::max(1, static_cast<int>(std::ceil(ext(i) / h_)) + 1);
  cells_.resize(static_cast<std::size_t>(dims_[0]) * static_cast<std::size_t>(dims_[1]) * static_cast<std::size_t>(dims_[2]));
  for (std::size_t t = 0; t < tris_.size(); ++t) {
    const Eigen::Vector3d &a = pts_[tris_[t][0]], &b = pts_[tris_[t][1]], &c = pts_[tris_[t][2]];
    const auto c0 = cell_of(a.cwiseMin(b).cwiseMin(c)), c1 = cell_of(a.cwiseMax(b).cwiseMax(c));
    for (int i = c0[0]; i <= c1[0]; ++i)
      for (int j = c0[1]; j <= c1[1]; ++j)
        for (int k = c0[2]; k <= c1[2]; ++k)
          cells_[(static_cast<std::size_t>(k) * static_cast<std::size_t>(dims_[1]) + static_cast<std::size_t>(j)) *
                     static_cast<std::size_t>(dims_[0]) + static_cast<std::size_t>(i)]
              .push_back(t);
  }
}

std::array<int, 3> SurfaceDistance::cell_of(const Eigen::Vector3d& p) const {
  std::array<int, 3> c{};
  for (int i = 0; i < 3; ++i)
    c[static_cast<std::size_t>(i)] = std::clamp(static_cast<int>(std::floor((p(i) - lo_(i)) / h_)), 0, dims_[static_cast<std::size_t>(i)] - 1);
  return c;
}

SurfaceDistance::Closest SurfaceDistance::closest(const Eigen::Vector3d& p) const {
  Closest best{std::numeric_limits<double>::infinity(), Eigen::Vector3d::Zero(), 0};
  const auto c = cell_of(p);
  // Distance from p to the grid box, so that ring bounds stay valid for outside points.
  const Eigen::Vector3d hi = lo_ + h_ * Eigen::Vector3d(dims_[0], dims_[1], dims_[2]);
  const double outside = (lo_ - p).cwiseMax(p - hi).cwiseMax(0.0).norm();
  const int max_ring = std::max({dims_[0], dims_[1], dims_[2]});
  for (int r = 0; r <= max_ring; ++r) {
    for (int i = c[0] - r; i <= c[0] + r; ++i) {
      if (i < 0 || i >= dims_[0]) continue;
      for (int j = c[1] - r; j <= c[1] + r; ++j) {
        if (j < 0 || j >= dims_[1]) continue;
        for (int k = c[2] - r; k <= c[2] + r; ++k) {
          if (k < 0 || k >= dims_[2]) continue;
          if (std::max({std::abs(i - c[0]), std::abs(j - c[1]), std::abs(k - c[2])}) != r) continue;
          for (std::size_t t : cells_[(static_cast<std::size_t>(k) * static_cast<std::size_t>(dims_[1]) + static_cast<std::size_t>(j)) *
                                          static_cast<std::size_t>(dims_[0]) + static_cast<std::size_t>(i)]) {
            const Eigen::Vector3d q = closest_on_triangle(p, pts_[tris_[t][0]], pts_[tris_[t][1]], pts_[tris_[t][2]]);
            const double d2 = (p - q).squaredNorm();
            if (d2 < best.distance2) best = {d2, q, t};
          }
        }
      }
    }
    // Cells in ring r+1 or beyond are at least r*h (+ the distance to the box) away.
    const double bound = outside + r * h_;
    if (best.distance2 <= bound * bound) break;
  }
  return best;
}

void SurfaceDistance::calibrate_inside(const std::vector<Eigen::Vector3d>& inside) {
  int votes = 0;
  orientation_ = 1.0;
  for (const auto& p : inside) votes += signed_distance(p) >= 0 ? 1 : -1;
  orientation_ = votes >= 0 ? 1.0 : -1.0;
}

double SurfaceDistance::signed_distance(const Eigen::Vector3d& p) const {
  const Closest c = closest(p);
  // Outward normals give (p - q).n < 0 inside; `orientation_` fixes the surface's convention.
  const double side = (p - c.point).dot(normals_[c.tri]) <= 0 ? 1.0 : -1.0;
  return orientation_ * side * std::sqrt(c.distance2);
}

}  // namespace stentsim::device_gen
