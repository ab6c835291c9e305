// The smoothing spline against real FITPACK: scipy 1.10's UnivariateSpline
// (Dierckx's Fortran curfit through dfitpack), run once offline by
// reference/scipy_curfit_reference.py; its data, knots, coefficients, fp and
// ier are stored as numbers in scipy_curfit_reference.inc, so CI needs no scipy.
// Cases: the hand-checked 11-point set, a noisy arc at five smoothing factors
// (two of which exhaust FITPACK's first knot storage and restart as scipy
// does), non-uniform weights, and the x, y, z coordinates of a case2-rca
// placement at zeta = 4, 0.001 and 1e-6.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "device_gen/fitpack/curfit.hpp"

namespace {

struct ScipyCase {
  std::string name;
  std::vector<double> x, y, w;
  double s;
  std::vector<double> t, c;  // full knot vector (n) and the n - k - 1 coefficients
  double fp;
  int ier;
};

#include "tests/device_gen/scipy_curfit_reference.inc"

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double a : v) m = std::max(m, std::abs(a));
  return m;
}

}  // namespace

TEST(DeviceGenFitpackScipy, KnotsCoefficientsAndResidualMatchFitpack) {
  const auto cases = all_scipy_cases();
  ASSERT_GE(cases.size(), 7u);
  for (const auto& ref : cases) {
    SCOPED_TRACE(ref.name);
    const auto fit = stentsim::device_gen::fitpack::univariate_spline(ref.x, ref.y, ref.w, ref.s);
    EXPECT_EQ(fit.ier, ref.ier);
    // Knots are data points chosen by the same rule: identical, not close.
    ASSERT_EQ(fit.spline.knots.size(), ref.t.size());
    for (std::size_t i = 0; i < ref.t.size(); ++i) EXPECT_EQ(fit.spline.knots[i], ref.t[i]) << "knot " << i;
    ASSERT_EQ(fit.spline.coefficients.size(), ref.c.size());
    // Same algorithm, different rounding (Givens order, rational interpolation of p).
    const double scale = std::max(1.0, max_abs(ref.c));
    double worst = 0;
    for (std::size_t j = 0; j < ref.c.size(); ++j) worst = std::max(worst, std::abs(fit.spline.coefficients[j] - ref.c[j]));
    EXPECT_LT(worst, 1e-9 * scale) << "max coefficient difference " << worst;
    EXPECT_NEAR(fit.residual, ref.fp, 1e-9 * std::max(ref.fp, ref.s)) << "fp";
    std::printf("%-12s m = %3zu  n = %2zu  ier = %2d  fp %.17g  |fp - fp_scipy| %.3g  max |c - c_scipy| %.3g\n",
                ref.name.c_str(), ref.x.size(), ref.t.size(), ref.ier, fit.residual, std::abs(fit.residual - ref.fp), worst);
  }
}
