#pragma once
// Distance queries to a triangulated surface (CGAL AABB tree behind a pimpl,
// so that this header stays light).
#include <Eigen/Core>

#include <memory>
#include <vector>

#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::segmentation {

class SurfaceDistance {
 public:
  explicit SurfaceDistance(const TriSurface& surface);
  ~SurfaceDistance();
  SurfaceDistance(const SurfaceDistance&) = delete;
  SurfaceDistance& operator=(const SurfaceDistance&) = delete;

  double distance(const Eigen::Vector3d& p) const;
  Eigen::Vector3d closest_point(const Eigen::Vector3d& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// For a closed, consistently oriented surface: whether each point is inside
/// (CGAL::Side_of_triangle_mesh). Throws ComputeError if the surface is not closed.
std::vector<bool> inside_closed_surface(const TriSurface& closed, const std::vector<Eigen::Vector3d>& points);

}  // namespace stentsim::segmentation
