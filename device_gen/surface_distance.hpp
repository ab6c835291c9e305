#pragma once
// Distance from points to a triangulated surface (the lumen), with a sign
// (positive inside) calibrated on points known to be inside (the centerline).
// A uniform grid of triangle bounding boxes; exact point-triangle distances
// (Ericson, Real-Time Collision Detection, 2005, 5.1.5).
#include <Eigen/Core>

#include <array>
#include <vector>

#include "common/mesh_data.hpp"

namespace stentsim::device_gen {

class SurfaceDistance {
 public:
  /// Triangles and quads (split) of `surface`; other cells are ignored.
  explicit SurfaceDistance(const MeshData& surface);
  std::size_t triangles() const { return tris_.size(); }
  /// Sets the sign so that the majority of `inside` points get positive distances.
  void calibrate_inside(const std::vector<Eigen::Vector3d>& inside);
  /// Unsigned distance and the side by the closest triangle's normal, times the calibration.
  double signed_distance(const Eigen::Vector3d& p) const;

 private:
  struct Closest {
    double distance2;
    Eigen::Vector3d point;
    std::size_t tri;
  };
  Closest closest(const Eigen::Vector3d& p) const;
  std::array<int, 3> cell_of(const Eigen::Vector3d& p) const;

  std::vector<Eigen::Vector3d> pts_;
  std::vector<std::array<std::size_t, 3>> tris_;
  std::vector<Eigen::Vector3d> normals_;
  Eigen::Vector3d lo_;
  double h_ = 1;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<std::vector<std::size_t>> cells_;
  double orientation_ = 1.0;
};

}  // namespace stentsim::device_gen
