#pragma once
// Cross-sections of a surface by a plane, as seen from a point on it: the
// polar contour (one radius per ray) the wall synthesis builds from and the
// patient mesh lofts through (DESIGN.md §5).
#include <Eigen/Core>

#include <utility>
#include <vector>

#include "common/mesh_data.hpp"

namespace stentsim {

/// The cut of the triangles and quads of `surface` by the plane through `o`
/// with unit normal `t`, as 2D segments in the (n, b) coordinates around `o`.
std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> plane_cut(const MeshData& surface, const Eigen::Vector3d& o,
                                                                   const Eigen::Vector3d& t, const Eigen::Vector3d& n,
                                                                   const Eigen::Vector3d& b);

/// Distance from the origin to the nearest segment along the unit direction
/// `dir`; NaN when the ray meets none.
double ray_hit(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& segments, const Eigen::Vector2d& dir);

}  // namespace stentsim
