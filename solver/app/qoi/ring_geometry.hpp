#pragma once
// The geometry of a deformed stent seen ring by ring (DESIGN.md §6, §8): each
// ring's centroid, its local axis (the tangent of the curve through the ring
// centroids), its mean diameter in the plane normal to that axis, the
// curvature of the centroid curve, and dogboning. Pure functions of node
// positions, so they are tested on their own.
#include <Eigen/Core>

#include <vector>

namespace stentsim::solver {

struct RingMeasure {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double diameter = 0.0;  // 2 · mean distance of the ring's nodes from the centroid, normal to the axis
};

/// Rings in order along the stent. With two or more rings the local axis is
/// the centroid curve's tangent (central differences, one-sided at the ends);
/// a single ring takes `single_ring_axis`.
std::vector<RingMeasure> measure_rings(const std::vector<std::vector<Eigen::Vector3d>>& ring_points,
                                       const Eigen::Vector3d& single_ring_axis);

/// The axis a lone ring's outward radial directions leave out: the eigenvector
/// of Σ e eᵀ with the smallest eigenvalue (the radial directions span the ring's plane).
Eigen::Vector3d axis_normal_to(const std::vector<Eigen::Vector3d>& radial_directions);

/// Largest discrete (Menger) curvature 4·area/(a·b·c) of consecutive centroid
/// triples [1/mm]; 0 with fewer than three rings.
double max_centroid_curvature(const std::vector<RingMeasure>& rings);

/// Dogboning of the ring diameters (Migliavacca 2002, DESIGN.md §8):
/// r_distal = the mean of the two end rings, r_central = the middle ring (the
/// mean of the two middle rings for an even count).
struct Dogboning {
  double distal = 0.0;   // 100 (r_distal − r_central) / r_distal [%]
  double central = 0.0;  // 100 (r_distal − r_central) / r_central [%]
};
Dogboning dogboning(const std::vector<double>& ring_diameters);

}  // namespace stentsim::solver
