// The stent's ring measures (solver/app/qoi/ring_geometry.hpp) on rings whose
// answers are known: circles of given diameter on straight, tilted and
// circular-arc axes.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

#include "solver/app/qoi/ring_geometry.hpp"

using namespace stentsim::solver;
using Eigen::Vector3d;

namespace {

/// n points of a zig-zag ring of diameter d around `center`, normal to `axis`
/// (axial offsets ±h alternate, like crowns, and must not change the diameter).
std::vector<Vector3d> ring(const Vector3d& center, const Vector3d& axis, double d, double h, int n = 16) {
  const Vector3d a = axis.normalized();
  const Vector3d e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  std::vector<Vector3d> p;
  for (int i = 0; i < n; ++i) {
    const double phi = 2 * std::numbers::pi * i / n;
    p.push_back(center + 0.5 * d * (std::cos(phi) * e1 + std::sin(phi) * e2) + (i % 2 ? h : -h) * a);
  }
  return p;
}

}  // namespace

TEST(RingGeometry, DiametersOfStraightAndTiltedStents) {
  for (const Vector3d axis : {Vector3d(0, 0, 1), Vector3d(1, 2, 3).normalized()}) {
    std::vector<std::vector<Vector3d>> rings;
    const std::vector<double> d{2.6, 2.4, 2.45, 2.7};
    for (int k = 0; k < 4; ++k) rings.push_back(ring(Vector3d(0.3, -0.2, 0.1) + 1.5 * k * axis, axis, d[k], 0.75));
    const auto m = measure_rings(rings, Vector3d::UnitX());
    ASSERT_EQ(m.size(), 4u);
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(m[k].diameter, d[k], 1e-12);
      EXPECT_NEAR(std::abs(m[k].axis.dot(axis)), 1.0, 1e-12);
    }
    EXPECT_NEAR(max_centroid_curvature(m), 0.0, 1e-12);
  }
}

TEST(RingGeometry, CentroidCurvatureOfAnArcAndTheAxisAlongIt) {
  // Ring centroids on a circle of radius 10 mm, each ring normal to the arc.
  const double R = 10.0, step = 0.15;
  std::vector<std::vector<Vector3d>> rings;
  for (int k = 0; k < 5; ++k) {
    const double th = step * k;
    const Vector3d c(R * std::cos(th), R * std::sin(th), 0), t(-std::sin(th), std::cos(th), 0);
    rings.push_back(ring(c, t, 2.5, 0.0));
  }
  const auto m = measure_rings(rings, Vector3d::UnitZ());
  EXPECT_NEAR(max_centroid_curvature(m), 1.0 / R, 1e-12);
  // Interior rings: the central-difference chord is parallel to the arc's tangent there.
  for (int k = 1; k < 4; ++k) EXPECT_NEAR(m[k].diameter, 2.5, 1e-12);
  // End rings: the one-sided chord is tilted by step/2; the in-plane distances shrink accordingly.
  EXPECT_GT(m[0].diameter, 2.5 * std::cos(step / 2) - 1e-9);
  EXPECT_LT(m[0].diameter, 2.5);
}

TEST(RingGeometry, ALoneRingTakesTheAxisItsRadialDirectionsLeaveOut) {
  const Vector3d axis = Vector3d(0.2, -1, 0.4).normalized();
  const Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  std::vector<Vector3d> radial;
  for (int i = 0; i < 8; ++i) {
    const double phi = 2 * std::numbers::pi * i / 8;
    radial.push_back(std::cos(phi) * e1 + std::sin(phi) * e2);
  }
  EXPECT_NEAR(std::abs(axis_normal_to(radial).dot(axis)), 1.0, 1e-12);
  const auto m = measure_rings({ring(Vector3d::Zero(), axis, 1.9, 0.5)}, axis_normal_to(radial));
  EXPECT_NEAR(m[0].diameter, 1.9, 1e-12);
  EXPECT_EQ(max_centroid_curvature(m), 0.0);
}

TEST(RingGeometry, DogboningByTheEndAndMiddleRings) {
  // Odd count: the middle ring; even count: the mean of the two middle rings.
  const Dogboning odd = dogboning({3.0, 2.0, 2.5, 2.2, 2.6});  // distal 2.8, central 2.5
  EXPECT_NEAR(odd.distal, 100 * 0.3 / 2.8, 1e-12);
  EXPECT_NEAR(odd.central, 100 * 0.3 / 2.5, 1e-12);
  const Dogboning even = dogboning({2.7, 2.4, 2.2, 2.5});  // distal 2.6, central 2.3
  EXPECT_NEAR(even.distal, 100 * 0.3 / 2.6, 1e-12);
  EXPECT_NEAR(even.central, 100 * 0.3 / 2.3, 1e-12);
  EXPECT_EQ(dogboning({2.0}).distal, 0.0);
  EXPECT_LT(dogboning({2.0, 2.5, 2.0}).distal, 0.0);  // a bulging middle is negative dogboning
}
