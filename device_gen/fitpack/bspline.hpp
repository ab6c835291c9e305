#pragma once
// A spline function in B-spline form with FITPACK's layout (Dierckx 1993,
// ch. 1): knots t[0..n), coefficients c[0..n-k-1), degree k. Evaluation
// clamps to the base interval [t[k], t[n-k-1]] like FITPACK's splev.
#include <vector>

namespace stentsim::device_gen::fitpack {

struct BSpline {
  std::vector<double> knots;
  std::vector<double> coefficients;  // n - k - 1 of them
  int degree = 3;

  double begin() const { return knots[static_cast<std::size_t>(degree)]; }
  double end() const { return knots[knots.size() - 1 - static_cast<std::size_t>(degree)]; }
  /// s(x) (order 0) or its derivative of the given order (<= degree).
  double evaluate(double x, int order = 0) const;
  double operator()(double x) const { return evaluate(x, 0); }
  /// Index l of the knot span t[l] <= x < t[l+1] used for x (clamped).
  std::size_t span(double x) const;
};

/// The k+1 B-splines of degree k that are non-zero at x in the span
/// t[l] <= x < t[l+1] (Cox-de Boor recurrence, Dierckx 1993 eq. 1.22).
/// Returns values for B_{l-k}..B_l.
std::vector<double> nonzero_basis(const std::vector<double>& t, int k, double x, std::size_t l);

}  // namespace stentsim::device_gen::fitpack
