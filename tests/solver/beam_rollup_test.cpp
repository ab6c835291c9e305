// Roll-up of a straight cantilever under an end moment 2πEI/L (issue 8): the
// exact solution is a full circle of radius L/(2π), the tip back at the root
// and rotated by 2π.
#include "solver/beams/beam_loads.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/rotation.hpp"
#include "tests/solver/beam_test_bodies.hpp"
#include "tests/solver/beam_test_system.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <numbers>

using namespace stentsim::solver;
using namespace stentsim::solver::beams;
using namespace stentsim::solver::beams::testing;

namespace {

constexpr double L = 10.0, E = 1e4, G = 5e3, I = 1.0 / 12.0;

struct RollupResult {
  double tip_error = 0.0;   // |r_tip − r_root|
  double tip_angle = 0.0;   // accumulated rotation of the tip triad about e_z
  int max_iterations = 0;
};

RollupResult rollup(int n, BeamInterpolation kind, int gauss_points = 0) {
  const BeamSection sec = BeamSection::from_values(E, G, 1.0, 1.0, 1.0, I, I, 1.0 / 6.0);
  BeamBodyDefinition def = curve_body(straight_x(), L, n, sec, kind, gauss_points);
  GlobalDof ndof = 0;
  auto dofs = number_beam_dofs(def, 0, &ndof);
  dofs[0].pos = dofs[0].rot = {-1, -1, -1};  // clamped root (tangent free: it carries the root shear strain)
  BeamTerm beam("cantilever", def, dofs);
  const double M = 2.0 * std::numbers::pi * E * I / L;
  NodalLoadTerm moment("tip moment", dofs[n].rot, Eigen::Vector3d(0, 0, M), [](double t) { return t; });
  TestSystem sys(ndof);
  sys.terms = {&beam, &moment};
  RollupResult r;
  Eigen::Quaterniond previous = beam.rotation(n);
  for (int step = 1; step <= 10; ++step) {
    r.max_iterations = std::max(r.max_iterations, sys.solve(0.1 * step, 1e-12 * L));
    const Eigen::Quaterniond now = beam.rotation(n);
    r.tip_angle += quat_log(now * previous.conjugate()).z();  // each step turns 36° < 180°
    previous = now;
  }
  r.tip_error = (beam.position(sys.u, n) - beam.position(sys.u, 0)).norm();
  return r;
}

}  // namespace

TEST(BeamRollup, HermiteConvergesWithOrderAboveThreeAndAHalf) {
  const int ns[4] = {4, 8, 16, 32};
  double e[4], angle_error[4];
  for (int i = 0; i < 4; ++i) {
    const RollupResult r = rollup(ns[i], BeamInterpolation::hermite3);
    e[i] = r.tip_error;
    angle_error[i] = std::abs(r.tip_angle - 2 * std::numbers::pi);
    std::printf("hermite N=%2d: e_N/L = %.3e, |tip angle − 2π| = %.2e, max Newton iterations %d\n", ns[i],
                r.tip_error / L, angle_error[i], r.max_iterations);
    if (i > 0) {
      EXPECT_LT(e[i], e[i - 1]);
      EXPECT_LT(angle_error[i], angle_error[i - 1]);
    }
  }
  EXPECT_LT(angle_error[3], 1e-6);  // N = 32
  const double order = std::log(e[1] / e[3]) / std::log(4.0);
  std::printf("observed order between N=8 and N=32: %.3f\n", order);
  EXPECT_GE(order, 3.5);
  EXPECT_LE(e[3], 1e-6 * L);
}

TEST(BeamRollup, LagrangeClosesExactlyForEqualElements) {
  for (int n : {4, 8}) {
    const RollupResult r = rollup(n, BeamInterpolation::lagrange2);
    std::printf("lagrange N=%d: e_N/L = %.3e, tip angle − 2π = %.2e\n", n, r.tip_error / L,
                r.tip_angle - 2 * std::numbers::pi);
    EXPECT_LE(r.tip_error, 1e-10 * L);
    EXPECT_NEAR(r.tip_angle, 2 * std::numbers::pi, 1e-9);
  }
}

// Not a pass criterion, so disabled: how the roll-up error depends on the Hermite quadrature.
// Run it with --gtest_also_run_disabled_tests --gtest_filter='*HermiteQuadratureStudy'.
TEST(BeamRollup, DISABLED_HermiteQuadratureStudy) {
  for (int gp : {3, 4, 5}) {
    std::printf("gauss points %d:", gp);
    for (int n : {4, 8, 16, 32}) std::printf("  e_%d/L=%.3e", n, rollup(n, BeamInterpolation::hermite3, gp).tip_error / L);
    std::printf("\n");
  }
}
