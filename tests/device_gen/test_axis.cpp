// The device axis: arc length and the rotation-minimizing frame against an
// independent parallel-transport integration (RK4 of n' = -(n . t') t).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "device_gen/device_axis.hpp"
#include "synthetic_curves.hpp"

using namespace stentsim::device_gen;

TEST(DeviceGenAxis, FrameTwistEqualsParallelTransportOnHelix) {
  const auto h = synthetic::helix(8.0, 3.0);  // curvature 0.11 /mm, torsion 0.041 /mm
  const SplineCurve curve = synthetic::fit_curve(h, 14.0);
  const DeviceAxis axis = DeviceAxis::along(curve, 7.0, 9.4, Eigen::Vector3d::UnitX());
  // Independent parallel transport: RK4 on n' = -(n . dt/ds) t, step 1e-3 mm.
  Eigen::Vector3d n = axis.frame(0.0).normal;
  auto rhs = [&](double s, const Eigen::Vector3d& v) {
    const AxisFrame f = axis.frame(s);
    return Eigen::Vector3d(-(v.dot(f.curvature)) * f.tangent);
  };
  const double step = 1e-3;
  double max_angle = 0, frenet_twist = 0;
  for (int i = 0; i < 9400; ++i) {
    const double s = i * step;
    const Eigen::Vector3d k1 = rhs(s, n), k2 = rhs(s + step / 2, n + step / 2 * k1), k3 = rhs(s + step / 2, n + step / 2 * k2),
                          k4 = rhs(s + step, n + step * k3);
    n += step / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    if ((i + 1) % 470 == 0) {
      const AxisFrame f = axis.frame(s + step);
      max_angle = std::max(max_angle, std::acos(std::min(1.0, f.normal.dot(n.normalized()))));
      EXPECT_NEAR(f.binormal.dot(f.tangent.cross(f.normal)), 1.0, 1e-14);
    }
  }
  EXPECT_LT(max_angle, 1e-8);
  // The helix does twist: the Frenet frame turns by torsion * length = 0.386 rad
  // relative to the rotation-minimizing one, which a Frenet-based frame would fail.
  const AxisFrame f0 = axis.frame(0.0), f1 = axis.frame(9.4);
  const Eigen::Vector3d p0 = f0.curvature.normalized(), p1 = f1.curvature.normalized();
  const double a0 = std::atan2(p0.dot(f0.binormal), p0.dot(f0.normal));
  const double a1 = std::atan2(p1.dot(f1.binormal), p1.dot(f1.normal));
  frenet_twist = std::remainder(a1 - a0, 2 * M_PI);
  EXPECT_NEAR(std::abs(frenet_twist), 3.0 / 73.0 * 9.4, 1e-4);
}

TEST(DeviceGenAxis, ArcLengthIsExactOnHelix) {
  const auto h = synthetic::helix(8.0, 3.0);
  const SplineCurve curve = synthetic::fit_curve(h, 14.0);
  const DeviceAxis axis = DeviceAxis::along(curve, 7.0, 9.4, Eigen::Vector3d::UnitX());
  // The spline interpolates the helix sampled by arc length: sigma matches the
  // helix arc length to the interpolation error, and positions lie on the helix.
  EXPECT_NEAR(axis.curve_length(), 14.0, 1e-5);
  for (double sg = 0; sg <= 9.4; sg += 0.94) EXPECT_LT((axis.position(sg) - h(sg + 7.0 - 4.7)).norm(), 5e-6);
  // Inverse of the arc-length map.
  for (double u = 0.05; u < 14.0; u += 1.3) EXPECT_NEAR(axis.curve_parameter(axis.curve_arc_length(u)), u, 1e-12);
}

TEST(DeviceGenAxis, StraightAxisIsCentred) {
  const DeviceAxis a = DeviceAxis::straight(9.4);
  EXPECT_TRUE(a.is_straight());
  EXPECT_LT((a.position(0) - Eigen::Vector3d(0, 0, -4.7)).norm(), 1e-15);
  const AxisFrame f = a.frame(3.0);
  EXPECT_LT((f.tangent - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
  EXPECT_LT((f.normal - Eigen::Vector3d::UnitX()).norm(), 1e-15);
  EXPECT_LT((f.binormal - Eigen::Vector3d::UnitY()).norm(), 1e-15);
}
