#pragma once
// Tangents, rotation-minimizing (parallel-transport) frames and arc length of
// a sampled curve. The frames use the double-reflection method of Wang,
// Jüttler, Zheng & Liu, "Computation of rotation minimizing frames", ACM TOG
// 27(1), 2008, which is exact for the discrete transport between samples.
#include <Eigen/Core>

#include <optional>
#include <vector>

namespace stentsim::segmentation {

struct Frames {
  std::vector<Eigen::Vector3d> tangent, normal, binormal;  // unit, right-handed (T, N, B)
};

/// Unit tangents by central differences (one-sided at the ends).
std::vector<Eigen::Vector3d> polyline_tangents(const std::vector<Eigen::Vector3d>& pts);

/// Parallel-transport frames along `pts`. The first normal is `first_normal`
/// made orthogonal to the first tangent, or a fixed choice when not given.
Frames parallel_transport_frames(const std::vector<Eigen::Vector3d>& pts,
                                 std::optional<Eigen::Vector3d> first_normal = std::nullopt);

/// Cumulative chord length, starting at 0.
std::vector<double> cumulative_length(const std::vector<Eigen::Vector3d>& pts);

/// Resamples a polyline at (as near as possible) equal `spacing`, keeping both
/// ends (linear interpolation between the given points).
std::vector<Eigen::Vector3d> resample_polyline(const std::vector<Eigen::Vector3d>& pts, double spacing);

/// Non-shrinking (Taubin lambda|mu) smoothing of a polyline sampled at equal
/// spacing: wavelengths shorter than about 4 `samples` samples are damped
/// (2 samples² iterations), longer ones kept; each point stays within
/// bound[i] of where it started, the ends are fixed. Returns the largest
/// displacement.
double smooth_with_bounded_displacement(std::vector<Eigen::Vector3d>& pts, const std::vector<double>& bound,
                                        double samples);

}  // namespace stentsim::segmentation
