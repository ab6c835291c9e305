#pragma once
// Cubic smoothing spline with automatic knots: P. Dierckx's algorithm
// (FITPACK curfit/fpcurf; Dierckx 1975 J. Comp. Appl. Math. 1:165, and
// "Curve and surface fitting with splines", 1993, ch. 5), re-implemented
// from the book and the published algorithm, step for step, so that the
// result equals FITPACK's (and scipy's UnivariateSpline's) up to rounding.
//
// Part 1 adds knots (each new knot at the middle data point of the knot
// interval with the largest residual sum, Dierckx 5.3) until the weighted
// least-squares spline has fp = sum (w_i (y_i - s(x_i)))^2 <= s. Part 2
// then smooths: the rows of the k-th derivative jumps at the interior
// knots, weighted 1/p, are appended to the observation matrix (Givens QR),
// and p is found by rational interpolation of f(p) (Dierckx 5.2.4) until
// |fp - s| < tol * s.
#include <limits>
#include <vector>

#include "device_gen/fitpack/bspline.hpp"

namespace stentsim::device_gen::fitpack {

struct SmoothingFit {
  BSpline spline;
  double residual = 0;   // fp = sum (w_i (y_i - s(x_i)))^2
  double smoothing = 0;  // the requested s
  double tolerance = 0;  // relative tolerance on |fp - s|
  /// FITPACK's ier: 0 the smoothing condition holds; -1 interpolating
  /// spline; -2 the least-squares polynomial of degree k already has fp <= s
  /// (the limit of large s); 1 storage exhausted, 2 iteration anomaly,
  /// 3 maxit reached (errors).
  int ier = 0;
  /// The smoothing parameter p of Part 2 (infinity when Part 2 did not run).
  double p = std::numeric_limits<double>::infinity();
  /// Least-squares polynomial residual fp0 (the upper bound of useful s).
  double polynomial_residual = 0;

  bool condition_met() const;
};

/// scipy.interpolate.UnivariateSpline(x, y, w, k, s) semantics: FITPACK with
/// iopt = 0 and nest = max(m/2, 2k+2) (s > 0), and when that storage is
/// exhausted (ier = 1) a continuation with iopt = 1 and nest = m + k + 1,
/// exactly as scipy restarts. tol and maxit as FITPACK's curfit (0.001, 20).
/// Throws std::invalid_argument for x not strictly increasing, w <= 0,
/// m <= k or s < 0.
SmoothingFit univariate_spline(const std::vector<double>& x, const std::vector<double>& y,
                               const std::vector<double>& w, double s, int k = 3, double tol = 0.001,
                               int maxit = 20);

/// Weighted residual sum fp of a spline on data.
double weighted_residual(const BSpline& s, const std::vector<double>& x, const std::vector<double>& y,
                         const std::vector<double>& w);

/// Meaning of a FITPACK ier code, for messages.
const char* describe_ier(int ier);

}  // namespace stentsim::device_gen::fitpack
