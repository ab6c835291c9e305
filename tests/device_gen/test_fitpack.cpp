// The smoothing spline (FITPACK curfit semantics) against independent
// references: a sympy/mpmath computation (reference/smoothing_spline_reference.py),
// an exactly representable cubic, a dense penalised least-squares solve and
// the large-smoothing limit.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "device_gen/fitpack/curfit.hpp"

using stentsim::device_gen::fitpack::BSpline;
using stentsim::device_gen::fitpack::univariate_spline;
using stentsim::device_gen::fitpack::weighted_residual;

namespace {

// Noisy samples of a planar arc coordinate: deterministic "noise".
void arc_data(int m, std::vector<double>& x, std::vector<double>& y, std::vector<double>& w) {
  x.resize(static_cast<std::size_t>(m));
  y.resize(x.size());
  w.assign(x.size(), 1.0);
  for (int i = 0; i < m; ++i) {
    x[static_cast<std::size_t>(i)] = 0.1 * i;
    const double s = 0.1 * i;
    y[static_cast<std::size_t>(i)] = 10.0 * std::sin(s / 10.0) + 0.3 * std::sin(3.1 * s) + 0.05 * std::sin(17.0 * i);
  }
}

}  // namespace

// Reference: tests/device_gen/reference/smoothing_spline_reference.py (sympy
// exact B-splines, mpmath 40 digits). Knots derived by hand there: one knot
// at the middle data point x = 5.
TEST(DeviceGenFitpack, MatchesIndependentReferenceOnHandCheckedCase) {
  const std::vector<double> x = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  const std::vector<double> y = {0, 0.1, 0.3, 0.2, 0.5, 1.2, 0.6, 0.4, 0.5, 0.3, 0.2};
  const std::vector<double> w = {1, 1, 1, 2, 1, 1, 1, 0.5, 1, 1, 1};
  const double s = 0.45;
  const auto fit = univariate_spline(x, y, w, s);
  EXPECT_EQ(fit.ier, 0);
  EXPECT_TRUE(fit.condition_met());
  EXPECT_LT(std::abs(fit.residual - s), 0.001 * s);
  EXPECT_NEAR(fit.polynomial_residual, 0.50847614268373740951, 1e-13);
  const std::vector<double> knots = {0, 0, 0, 0, 5, 10, 10, 10, 10};
  ASSERT_EQ(fit.spline.knots.size(), knots.size());
  for (std::size_t i = 0; i < knots.size(); ++i) EXPECT_DOUBLE_EQ(fit.spline.knots[i], knots[i]);
  const double c_ref[] = {0.0082001213693837758, -0.058592070911428401, 1.0038118559766748, 0.63276853529495736,
                          0.1105250083794712};
  const double dc_dfp[] = {-0.59584861836425599, 2.3782495086603298, -4.1157195152776211, 2.7041369310691641,
                           -0.66582047049179894};
  ASSERT_EQ(fit.spline.coefficients.size(), 5u);
  for (std::size_t j = 0; j < 5; ++j) {
    // FITPACK stops inside |fp - s| < 0.001 s: compare at its own fp to first order.
    const double expected = c_ref[j] + dc_dfp[j] * (fit.residual - s);
    EXPECT_NEAR(fit.spline.coefficients[j], expected, 1e-8) << "coefficient " << j;
    EXPECT_NEAR(fit.spline.coefficients[j], c_ref[j], 1e-4) << "coefficient " << j;
  }
  EXPECT_NEAR(fit.spline(2.5), 0.23696295378964847, 1e-4);
  EXPECT_NEAR(fit.spline(7.25), 0.66305138797129537, 1e-4);
  EXPECT_NEAR(weighted_residual(fit.spline, x, y, w), fit.residual, 1e-14);
}

// A cubic is reproduced exactly; its B-spline coefficients on one interval
// are its Bezier control points (derived by hand: p(x) = 1 - 2x + x^2/2 + x^3/10
// on [0, 4], u = x/4: p = 1 - 8u + 8u^2 + 6.4u^3 -> 1, -5/3, -5/3, 7.4).
TEST(DeviceGenFitpack, ExactCubicGivesBezierCoefficients) {
  std::vector<double> x, y, w;
  for (int i = 0; i <= 8; ++i) {
    const double xi = 0.5 * i;
    x.push_back(xi);
    y.push_back(1 - 2 * xi + 0.5 * xi * xi + 0.1 * xi * xi * xi);
    w.push_back(1.0);
  }
  const auto fit = univariate_spline(x, y, w, 0.01);
  EXPECT_EQ(fit.ier, -2);
  ASSERT_EQ(fit.spline.knots.size(), 8u);
  const double bezier[] = {1.0, -5.0 / 3.0, -5.0 / 3.0, 7.4};
  for (std::size_t j = 0; j < 4; ++j) EXPECT_NEAR(fit.spline.coefficients[j], bezier[j], 1e-12);
  EXPECT_LT(fit.residual, 1e-24);
}

// zeta -> large: no interior knots; the fit is the least-squares cubic, and
// for data on a line it is that line.
TEST(DeviceGenFitpack, LargeSmoothingGivesLeastSquaresCubicAndLine) {
  std::vector<double> x, y, w;
  arc_data(95, x, y, w);
  const auto fit = univariate_spline(x, y, w, 1e9);
  EXPECT_EQ(fit.ier, -2);
  EXPECT_EQ(fit.spline.knots.size(), 8u);
  // Independent least squares in the monomial basis (Householder QR).
  Eigen::MatrixXd A(static_cast<Eigen::Index>(x.size()), 4);
  Eigen::VectorXd b(static_cast<Eigen::Index>(x.size()));
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const double xi = x[static_cast<std::size_t>(i)] / 9.4;
    A.row(i) << 1, xi, xi * xi, xi * xi * xi;
    b(i) = y[static_cast<std::size_t>(i)];
  }
  const Eigen::VectorXd a = A.householderQr().solve(b);
  for (double xi = 0; xi <= 9.4; xi += 0.37) {
    const double u = xi / 9.4;
    EXPECT_NEAR(fit.spline(xi), a(0) + a(1) * u + a(2) * u * u + a(3) * u * u * u, 1e-10);
  }
  // Straight data: the spline is the line, its second derivative vanishes.
  for (std::size_t i = 0; i < x.size(); ++i) y[i] = 2.0 + 0.5 * x[i];
  const auto line = univariate_spline(x, y, w, 4.0);
  EXPECT_EQ(line.ier, -2);
  for (double xi = 0; xi <= 9.4; xi += 0.1) {
    EXPECT_NEAR(line.spline(xi), 2.0 + 0.5 * xi, 1e-12);
    EXPECT_NEAR(line.spline.evaluate(xi, 2), 0.0, 1e-10);
  }
}

// The smoothing condition |fp - s| < 0.001 s holds for a range of s, including
// small s where the knot storage of the first call is exhausted and the fit
// continues as scipy's UnivariateSpline does; every interior knot is a data
// point; the reported fp equals the recomputed residual.
TEST(DeviceGenFitpack, SmoothingConditionHoldsAcrossSmoothingFactors) {
  std::vector<double> x, y, w;
  arc_data(95, x, y, w);
  for (double s : {4.0, 1.0, 0.2, 0.05, 0.01}) {
    const auto fit = univariate_spline(x, y, w, s);
    ASSERT_EQ(fit.ier, 0) << "s = " << s;
    EXPECT_TRUE(fit.condition_met()) << "s = " << s;
    EXPECT_NEAR(weighted_residual(fit.spline, x, y, w), fit.residual, 1e-10 * s);
    const auto& t = fit.spline.knots;
    for (std::size_t i = 4; i + 4 < t.size(); ++i) {
      bool on_data = false;
      for (double xi : x) on_data = on_data || xi == t[i];
      EXPECT_TRUE(on_data) << "knot " << t[i];
    }
    if (s == 0.01) {
      EXPECT_GT(t.size(), 47u) << "the continuation path was not exercised";
    }
  }
}

// Part 2 independently: with the knots FITPACK chose, the smoothing spline is
// the minimiser of sum (w (y - s))^2 + lam * sum (jumps of s''')^2 for the lam
// that gives the same fp (Dierckx 1993, 5.2). Dense normal equations, lam by bisection.
TEST(DeviceGenFitpack, SmoothingSplineIsThePenalisedLeastSquaresSolution) {
  std::vector<double> x, y, w;
  arc_data(95, x, y, w);
  for (std::size_t i = 0; i < w.size(); ++i) w[i] = 1.0 + 0.5 * std::cos(0.3 * static_cast<double>(i));
  const auto fit = univariate_spline(x, y, w, 0.5);
  ASSERT_EQ(fit.ier, 0);
  const auto& t = fit.spline.knots;
  const std::size_t nc = t.size() - 4;
  Eigen::MatrixXd A(static_cast<Eigen::Index>(x.size()), static_cast<Eigen::Index>(nc));
  Eigen::MatrixXd J(static_cast<Eigen::Index>(t.size() - 8), static_cast<Eigen::Index>(nc));
  for (std::size_t j = 0; j < nc; ++j) {
    BSpline e{t, std::vector<double>(nc, 0.0), 3};
    e.coefficients[j] = 1.0;
    for (std::size_t i = 0; i < x.size(); ++i) A(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = w[i] * e(x[i]);
    for (std::size_t r = 0; r < t.size() - 8; ++r) {
      const double knot = t[r + 4];
      const double left = 0.5 * (t[r + 3] + knot), right = 0.5 * (knot + t[r + 5]);
      J(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(j)) = e.evaluate(right, 3) - e.evaluate(left, 3);
    }
  }
  Eigen::VectorXd b(static_cast<Eigen::Index>(x.size()));
  for (std::size_t i = 0; i < x.size(); ++i) b(static_cast<Eigen::Index>(i)) = w[i] * y[i];
  auto solve = [&](double lam) -> Eigen::VectorXd {
    const Eigen::MatrixXd M = A.transpose() * A + lam * J.transpose() * J;
    return M.ldlt().solve(A.transpose() * b);
  };
  auto fp = [&](double lam) { return (b - A * solve(lam)).squaredNorm(); };
  double lo = -40, hi = 20;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (fp(std::exp(mid)) > fit.residual ? hi : lo) = mid;
  }
  const Eigen::VectorXd c = solve(std::exp(0.5 * (lo + hi)));
  for (std::size_t j = 0; j < nc; ++j) EXPECT_NEAR(fit.spline.coefficients[j], c(static_cast<Eigen::Index>(j)), 1e-7);
}

TEST(DeviceGenFitpack, RejectsBadData) {
  EXPECT_THROW(univariate_spline({0, 1, 1, 2, 3}, {0, 0, 0, 0, 0}, {1, 1, 1, 1, 1}, 1.0), std::invalid_argument);
  EXPECT_THROW(univariate_spline({0, 1, 2, 3, 4}, {0, 0, 0, 0, 0}, {1, 1, 0, 1, 1}, 1.0), std::invalid_argument);
  EXPECT_THROW(univariate_spline({0, 1, 2}, {0, 0, 0}, {1, 1, 1}, 1.0), std::invalid_argument);
}
