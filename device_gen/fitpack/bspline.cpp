#include "device_gen/fitpack/bspline.hpp"

#include <algorithm>
#include <stdexcept>

namespace stentsim::device_gen::fitpack {

std::size_t BSpline::span(double x) const {
  const auto k = static_cast<std::size_t>(degree);
  const std::size_t n = knots.size();
  if (n < 2 * k + 2 || coefficients.size() < n - k - 1)
    throw std::invalid_argument("BSpline: fewer knots or coefficients than the degree needs");
  const std::size_t last = n - k - 2;  // the last span of the base interval
  x = std::clamp(x, begin(), end());
  // First knot strictly greater than x, among t[k+1..n-k-1].
  auto it = std::upper_bound(knots.begin() + static_cast<std::ptrdiff_t>(k + 1),
                             knots.begin() + static_cast<std::ptrdiff_t>(n - k - 1), x);
  const auto l = static_cast<std::size_t>(it - knots.begin()) - 1;
  return std::min(l, last);
}

double BSpline::evaluate(double x, int order) const {
  if (order < 0 || order > degree) return 0.0;
  const int k = degree;
  x = std::clamp(x, begin(), end());
  const std::size_t l = span(x);
  // Active coefficients c[l-k..l]; differencing them `order` times gives the
  // coefficients of the derivative, a spline of degree k-order on the same
  // knots (de Boor 1978, ch. X, eq. 10): c_i <- (k-r+1)(c_i - c_{i-1})/(t_{i+k-r+1} - t_i).
  std::vector<double> d(static_cast<std::size_t>(k + 1));
  for (int j = 0; j <= k; ++j) d[static_cast<std::size_t>(j)] = coefficients[l - static_cast<std::size_t>(k) + static_cast<std::size_t>(j)];
  for (int r = 1; r <= order; ++r) {
    for (int j = k; j >= r; --j) {
      const std::size_t i = l - static_cast<std::size_t>(k) + static_cast<std::size_t>(j);
      const double h = knots[i + static_cast<std::size_t>(k - r + 1)] - knots[i];
      d[static_cast<std::size_t>(j)] = h > 0 ? (k - r + 1) * (d[static_cast<std::size_t>(j)] - d[static_cast<std::size_t>(j - 1)]) / h : 0.0;
    }
  }
  // de Boor's algorithm for the remaining degree p on d[order..k].
  const int p = k - order;
  std::vector<double> e(d.begin() + order, d.end());
  for (int r = 1; r <= p; ++r) {
    for (int j = p; j >= r; --j) {
      const std::size_t lo = l - static_cast<std::size_t>(p) + static_cast<std::size_t>(j);
      const std::size_t hi = l + 1 + static_cast<std::size_t>(j) - static_cast<std::size_t>(r);
      const double alpha = (x - knots[lo]) / (knots[hi] - knots[lo]);
      e[static_cast<std::size_t>(j)] = (1 - alpha) * e[static_cast<std::size_t>(j - 1)] + alpha * e[static_cast<std::size_t>(j)];
    }
  }
  return e[static_cast<std::size_t>(p)];
}

std::vector<double> nonzero_basis(const std::vector<double>& t, int k, double x, std::size_t l) {
  std::vector<double> h(static_cast<std::size_t>(k + 1), 0.0), hh(static_cast<std::size_t>(k + 1), 0.0);
  h[0] = 1.0;
  for (int j = 1; j <= k; ++j) {
    std::copy(h.begin(), h.begin() + j, hh.begin());
    h[0] = 0.0;
    for (int i = 1; i <= j; ++i) {
      const std::size_t li = l + static_cast<std::size_t>(i);
      const std::size_t lj = li - static_cast<std::size_t>(j);
      const double f = hh[static_cast<std::size_t>(i - 1)] / (t[li] - t[lj]);
      h[static_cast<std::size_t>(i - 1)] += f * (t[li] - x);
      h[static_cast<std::size_t>(i)] = f * (x - t[lj]);
    }
  }
  return h;
}

}  // namespace stentsim::device_gen::fitpack
