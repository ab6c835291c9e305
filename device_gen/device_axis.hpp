#pragma once
// The device axis: the curve the balloon and the stent are built along,
// parametrised by arc length sigma in [0, length] (the balloon's proximal end
// at 0, the stent midpoint at length/2), with a rotation-minimizing frame
// (zero twist, Bishop 1975; computed by the double reflection method of
// Wang, Juettler, Zheng, Liu, ACM TOG 27(1), 2008).
//
// Built either straight (+z, centred at the origin: the straight free expansion
// and the generic artery) or along the balloon centerline spline of the
// placement (a patient, a curved free expansion). Where the device
// reaches beyond the spline's ends (smoothing may shorten the curve by a
// few micrometres) the axis continues along the end tangent.
#include <Eigen/Core>

#include <optional>
#include <vector>

#include "device_gen/spline_curve.hpp"

namespace stentsim::device_gen {

struct AxisFrame {
  Eigen::Vector3d position, tangent;
  Eigen::Vector3d normal, binormal;  // rotation-minimizing; binormal = tangent x normal
  Eigen::Vector3d curvature;         // d tangent / d sigma
};

class DeviceAxis {
 public:
  /// Straight axis along +z, sigma = 0 at z = -length/2; normal +x.
  static DeviceAxis straight(double length);
  /// Along `curve` (parameter = arc length of the source centerline); the
  /// axis midpoint sigma = length/2 is the curve point at parameter u_mid,
  /// distances along the curve are its true arc length. `initial_normal` is
  /// projected onto the plane normal to the tangent at sigma = 0.
  static DeviceAxis along(const SplineCurve& curve, double u_mid, double length, const Eigen::Vector3d& initial_normal);

  double length() const { return length_; }
  bool is_straight() const { return !curve_; }
  Eigen::Vector3d position(double sigma) const;
  AxisFrame frame(double sigma) const;
  /// Largest curvature |d tangent/d sigma| over the frame grid.
  double max_curvature() const;
  /// Arc length of the spline from its start to parameter u (Gauss-Legendre).
  double curve_arc_length(double u) const;
  /// Spline parameter where the curve's arc length from its start is s.
  double curve_parameter(double s) const;
  double curve_length() const { return table_s_.empty() ? 0.0 : table_s_.back(); }
  /// Offset: sigma = (curve arc length) - offset.
  double offset() const { return offset_; }

 private:
  struct Point {
    Eigen::Vector3d position, tangent, curvature;
  };
  Point point(double sigma) const;

  double length_ = 0;
  std::optional<SplineCurve> curve_;
  double offset_ = 0;
  std::vector<double> table_u_, table_s_;  // arc length at sub-interval ends
  double grid_step_ = 0;
  std::vector<Eigen::Vector3d> grid_normal_;  // rotation-minimizing normal at sigma = i * grid_step_

  void build_frames(const Eigen::Vector3d& initial_normal);
};

/// One double-reflection step: carries the normal r0 at (x0, t0) to (x1, t1).
Eigen::Vector3d double_reflection(const Eigen::Vector3d& x0, const Eigen::Vector3d& t0, const Eigen::Vector3d& r0,
                                  const Eigen::Vector3d& x1, const Eigen::Vector3d& t1);

}  // namespace stentsim::device_gen
