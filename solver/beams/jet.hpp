#pragma once
// A second-order forward-mode automatic-differentiation scalar: value, gradient
// and Hessian with respect to N independent variables.
//
// Why: the beam tangent is the derivative of the residual with respect to
// multiplicative rotation increments (term.hpp). Writing the element energy
// once, templated on the scalar, and evaluating it with Jet<N> over the N
// rotational perturbations of an element gives the exact gradient (residual)
// and Hessian; the tangent then follows by a closed-form correction
// (beam_kernel.hpp). The additive DOFs enter linearly through r' and are
// differentiated by hand, so N stays small (9 for the Hermite element).
#include <Eigen/Core>

#include <cmath>

namespace stentsim::solver::beams {

template <int N>
struct Jet {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  double v = 0.0;
  Vec g{Vec::Zero()};
  Mat H{Mat::Zero()};

  Jet() = default;
  Jet(double c) : v(c) {}  // NOLINT: implicit constants are the point
  /// The full Hessian. Only the upper triangle of H is computed (it is
  /// symmetric; this halves the work of the products); the lower stays zero.
  Mat hessian() const {
    Mat full = H;
    full.template triangularView<Eigen::StrictlyLower>() = H.transpose().template triangularView<Eigen::StrictlyLower>();
    return full;
  }
  static Jet variable(double value, int i) {
    Jet j(value);
    j.g[i] = 1.0;
    return j;
  }
  Jet& operator+=(const Jet& o) { v += o.v; g += o.g; H += o.H; return *this; }
  Jet& operator-=(const Jet& o) { v -= o.v; g -= o.g; H -= o.H; return *this; }
  Jet& operator*=(double c) { v *= c; g *= c; H *= c; return *this; }
};

inline double value(double x) { return x; }
template <int N>
double value(const Jet<N>& x) { return x.v; }

/// First-order part of a Jet (value and gradient), for quantities whose
/// Hessian is not needed.
template <int N>
struct Grad {
  double v = 0.0;
  Eigen::Matrix<double, N, 1> g{Eigen::Matrix<double, N, 1>::Zero()};
  Grad() = default;
  Grad(double c) : v(c) {}  // NOLINT
  Grad(const Jet<N>& j) : v(j.v), g(j.g) {}  // NOLINT
};
template <int N>
Grad<N> operator*(const Grad<N>& a, const Grad<N>& b) {
  Grad<N> r(a.v * b.v);
  r.g = a.v * b.g + b.v * a.g;
  return r;
}
template <int N>
Grad<N> operator+(Grad<N> a, const Grad<N>& b) {
  a.v += b.v;
  a.g += b.g;
  return a;
}
template <int N>
Grad<N> operator-(Grad<N> a, const Grad<N>& b) {
  a.v -= b.v;
  a.g -= b.g;
  return a;
}

template <int N>
Jet<N> operator-(const Jet<N>& a) {
  Jet<N> r;
  r.v = -a.v; r.g = -a.g; r.H = -a.H;
  return r;
}
template <int N>
Jet<N> operator+(Jet<N> a, const Jet<N>& b) { return a += b; }
template <int N>
Jet<N> operator-(Jet<N> a, const Jet<N>& b) { return a -= b; }
template <int N>
Jet<N> operator+(Jet<N> a, double b) { a.v += b; return a; }
template <int N>
Jet<N> operator+(double b, Jet<N> a) { a.v += b; return a; }
template <int N>
Jet<N> operator-(Jet<N> a, double b) { a.v -= b; return a; }
template <int N>
Jet<N> operator-(double b, const Jet<N>& a) { return (-a) + b; }
template <int N>
Jet<N> operator*(Jet<N> a, double b) { return a *= b; }
template <int N>
Jet<N> operator*(double b, Jet<N> a) { return a *= b; }
template <int N>
Jet<N> operator*(const Jet<N>& a, const Jet<N>& b) {
  // One fused pass over the Hessian (the outer products as Eigen
  // expressions would go through temporaries; this is the hot spot).
  Jet<N> r;
  r.v = a.v * b.v;
  for (int i = 0; i < N; ++i) r.g[i] = a.v * b.g[i] + b.v * a.g[i];
  for (int j = 0; j < N; ++j) {
    const double agj = a.g[j], bgj = b.g[j];
    for (int i = 0; i <= j; ++i) r.H(i, j) = a.v * b.H(i, j) + b.v * a.H(i, j) + a.g[i] * bgj + b.g[i] * agj;
  }
  return r;
}
/// f(a) with f' = d1 and f'' = d2 at a.v (chain rule to second order).
template <int N>
Jet<N> chain(const Jet<N>& a, double f, double d1, double d2) {
  Jet<N> r;
  r.v = f;
  for (int i = 0; i < N; ++i) r.g[i] = d1 * a.g[i];
  for (int j = 0; j < N; ++j) {
    const double c = d2 * a.g[j];
    for (int i = 0; i <= j; ++i) r.H(i, j) = d1 * a.H(i, j) + c * a.g[i];
  }
  return r;
}
template <int N>
Jet<N> operator/(const Jet<N>& a, const Jet<N>& b) {
  const double iv = 1.0 / b.v;
  return a * chain(b, iv, -iv * iv, 2.0 * iv * iv * iv);
}
template <int N>
Jet<N> operator/(const Jet<N>& a, double b) { return a * (1.0 / b); }
template <int N>
Jet<N> operator/(double a, const Jet<N>& b) {
  const double iv = 1.0 / b.v;
  return chain(b, a * iv, -a * iv * iv, 2.0 * a * iv * iv * iv);
}
template <int N>
Jet<N> sqrt(const Jet<N>& a) {
  const double s = std::sqrt(a.v);
  return chain(a, s, 0.5 / s, -0.25 / (s * a.v));
}
template <int N>
Jet<N> sin(const Jet<N>& a) { return chain(a, std::sin(a.v), std::cos(a.v), -std::sin(a.v)); }
template <int N>
Jet<N> cos(const Jet<N>& a) { return chain(a, std::cos(a.v), -std::sin(a.v), -std::cos(a.v)); }
template <int N>
Jet<N> atan(const Jet<N>& a) {
  const double d = 1.0 / (1.0 + a.v * a.v);
  return chain(a, std::atan(a.v), d, -2.0 * a.v * d * d);
}

}  // namespace stentsim::solver::beams
