#pragma once
// Pairs of triangles of a surface that intersect one another other than along
// the edges and vertices they share: a segmented lumen that crosses itself, a
// balloon or a wall folded through itself in a solve (self-contact is not
// modelled, paper 2.5). CGAL's Polygon Mesh Processing does the work behind
// self_intersection_cgal.cpp, so CGAL's headers stay out of every caller.
#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <utility>
#include <vector>

namespace stentsim {

/// At most `limit` intersecting pairs (indices into `triangles`, first < second). Triangles
/// that would make the surface non-manifold where they join it are left out of the test.
std::vector<std::pair<int, int>> self_intersecting_triangles(const std::vector<Eigen::Vector3d>& points,
                                                             const std::vector<std::array<int, 3>>& triangles,
                                                             std::size_t limit);

}  // namespace stentsim
