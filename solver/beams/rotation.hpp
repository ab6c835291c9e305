#pragma once
// Rotation algebra on SO(3), templated on the scalar so that the beam energy
// can be evaluated in double and in Jet<N> (jet.hpp) with one code path.
//
// Conventions (used throughout solver/beams):
// - Unit quaternions q = (w, x, y, z), Hamilton product; q_a ⊗ q_b <-> Λ_a Λ_b
//   (the same as Eigen::Quaterniond).
// - A triad Λ = [d1 d2 d3] maps material (section) vectors to spatial ones.
// - exp(ψ): rotation by |ψ| about ψ (Rodrigues); log is its inverse with the
//   angle in [0, π] (quaternion chosen with w ≥ 0).
// - Spatial (left) increments: Λ <- exp(S(Δθ)) Λ, i.e. q <- qexp(Δθ) ⊗ q
//   (Simo & Vu-Quoc 1986, eq. 2.6; Crisfield & Jelenić 1999, eq. 2.2).
// - Right Jacobian (Crisfield & Jelenić 1999, eq. 3.4 with the curvature in the
//   material frame): for Λ = Λ_r exp(S(ψ(s))) with constant Λ_r,
//   Λᵀ Λ' = S(J_r(ψ) ψ'),  J_r(ψ) = I − (1 − cos θ)/θ² S(ψ) + (θ − sin θ)/θ³ S(ψ)².
// Near θ = 0 the trigonometric quotients are replaced by their Taylor series
// in θ² so that value, gradient and Hessian stay exact (no 0/0 in Jet).
#include "solver/beams/jet.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <numbers>

namespace stentsim::solver::beams {

template <class S>
using V3 = std::array<S, 3>;
/// 3x3 matrix, row-major: m[3*i + j] = m_ij.
template <class S>
using M3 = std::array<S, 9>;

template <class S>
struct Quat {
  S w, x, y, z;
};

template <class S>
V3<S> cross(const V3<S>& a, const V3<S>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
template <class S>
S dot(const V3<S>& a, const V3<S>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

template <class S>
Quat<S> qmul(const Quat<S>& a, const Quat<S>& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}
template <class S>
Quat<S> qconj(const Quat<S>& a) {
  return {a.w, -a.x, -a.y, -a.z};
}
template <class S>
Quat<S> qconst(const Eigen::Quaterniond& q) {
  return {S(q.w()), S(q.x()), S(q.y()), S(q.z())};
}

/// qexp(ψ): the unit quaternion of exp(S(ψ)).
template <class S>
Quat<S> qexp(const V3<S>& psi) {
  const S t2 = dot(psi, psi);
  S c, sh;  // cos(θ/2), sin(θ/2)/θ
  if (value(t2) < 1e-4) {
    c = 1.0 + t2 * (-1.0 / 8 + t2 * (1.0 / 384 + t2 * (-1.0 / 46080 + t2 * (1.0 / 10321920))));
    sh = 0.5 + t2 * (-1.0 / 48 + t2 * (1.0 / 3840 + t2 * (-1.0 / 645120 + t2 * (1.0 / 185794560))));
  } else {
    using std::cos, std::sin, std::sqrt;
    const S t = sqrt(t2);
    c = cos(0.5 * t);
    sh = sin(0.5 * t) / t;
  }
  return {c, sh * psi[0], sh * psi[1], sh * psi[2]};
}

/// The rotation of a perturbation variable h, exact to second order at h = 0:
/// (1 − |h|²/8, h/2). Value, gradient and Hessian at h = 0 equal qexp's.
template <class S>
Quat<S> qexp_second_order(const V3<S>& h) {
  return {1.0 - 0.125 * dot(h, h), 0.5 * h[0], 0.5 * h[1], 0.5 * h[2]};
}

/// log: the rotation vector (angle in [0, π]) of a unit quaternion.
template <class S>
V3<S> qlog(Quat<S> q) {
  if (value(q.w) < 0.0) q = {-q.w, -q.x, -q.y, -q.z};
  const V3<S> v{q.x, q.y, q.z};
  const S vv = dot(v, v);
  S f;  // ψ = f v
  const double wv = value(q.w);
  if (value(vv) < 1e-4 * wv * wv) {
    // 2 atan(x)/x / w with x² = |v|²/w², series to x^10 (next term < 1e-24).
    const S x2 = vv / (q.w * q.w);
    f = 2.0 * (1.0 + x2 * (-1.0 / 3 + x2 * (1.0 / 5 + x2 * (-1.0 / 7 + x2 * (1.0 / 9 + x2 * (-1.0 / 11)))))) / q.w;
  } else {
    using std::atan, std::sqrt;
    const S s = sqrt(vv);
    const S half = value(s) < wv ? atan(s / q.w) : std::numbers::pi / 2 - atan(q.w / s);
    f = 2.0 * half / s;
  }
  return {f * v[0], f * v[1], f * v[2]};
}

/// Rotation matrix of a unit quaternion.
template <class S>
M3<S> qmat(const Quat<S>& q) {
  const S xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
  const S xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
  const S wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
  return {1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz),       2.0 * (xz + wy),
          2.0 * (xy + wz),       1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx),
          2.0 * (xz - wy),       2.0 * (yz + wx),       1.0 - 2.0 * (xx + yy)};
}

/// J_r(ψ) v = v − a ψ×v + b ψ×(ψ×v), a = (1 − cos θ)/θ², b = (θ − sin θ)/θ³.
template <class S>
V3<S> right_jacobian_times(const V3<S>& psi, const V3<S>& v) {
  const S t2 = dot(psi, psi);
  S a, b;
  if (value(t2) < 1e-2) {
    a = 0.5 + t2 * (-1.0 / 24 + t2 * (1.0 / 720 + t2 * (-1.0 / 40320 + t2 * (1.0 / 3628800))));
    b = 1.0 / 6 + t2 * (-1.0 / 120 + t2 * (1.0 / 5040 + t2 * (-1.0 / 362880 + t2 * (1.0 / 39916800))));
  } else {
    using std::cos, std::sin, std::sqrt;
    const S t = sqrt(t2);
    a = (1.0 - cos(t)) / t2;
    b = (t - sin(t)) / (t2 * t);
  }
  const V3<S> pv = cross(psi, v);
  const V3<S> ppv = cross(psi, pv);
  return {v[0] - a * pv[0] + b * ppv[0], v[1] - a * pv[1] + b * ppv[1], v[2] - a * pv[2] + b * ppv[2]};
}

/// The SO(3) coefficient functions as functions of t2 = θ², with their first
/// and second t2-derivatives (for Jet chain rules without 0/0):
///   kind 0: α = sin θ/θ,  kind 1: a = (1 − cos θ)/θ²,  kind 2: b = (θ − sin θ)/θ³.
/// exp(S(ψ)) v = v + α ψ×v + a ψ×(ψ×v);  J_r(ψ) v = v − a ψ×v + b ψ×(ψ×v).
struct CoefficientValue {
  double f, d1, d2;
};
inline CoefficientValue rotation_coefficient(int kind, double t2) {
  if (t2 < 0.25) {
    // Σ_k (−1)^k t2^k / (2k + 1 + kind)!, 12 terms (remainder < 1e-30)
    double c[12];
    double fact = 1.0;
    for (int m = 2; m <= 1 + kind; ++m) fact *= m;  // (1 + kind)!
    for (int k = 0; k < 12; ++k) {
      if (k > 0) fact *= (2.0 * k + kind) * (2.0 * k + 1 + kind);
      c[k] = (k % 2 ? -1.0 : 1.0) / fact;
    }
    double f = 0, d1 = 0, d2 = 0;
    for (int k = 11; k >= 0; --k) f = f * t2 + c[k];
    for (int k = 11; k >= 1; --k) d1 = d1 * t2 + k * c[k];
    for (int k = 11; k >= 2; --k) d2 = d2 * t2 + k * (k - 1.0) * c[k];
    return {f, d1, d2};
  }
  const double t = std::sqrt(t2), s = std::sin(t), c = std::cos(t);
  const double t3 = t2 * t, t4 = t2 * t2, t5 = t4 * t;
  double f, f1, f2;  // f(θ), f'(θ), f''(θ)
  if (kind == 0) {
    f = s / t;
    f1 = (t * c - s) / t2;
    f2 = -s / t - 2 * c / t2 + 2 * s / t3;
  } else if (kind == 1) {
    f = (1 - c) / t2;
    f1 = s / t2 - 2 * (1 - c) / t3;
    f2 = c / t2 - 4 * s / t3 + 6 * (1 - c) / t4;
  } else {
    f = (t - s) / t3;
    f1 = (1 - c) / t3 - 3 * (t - s) / t4;
    f2 = s / t3 - 6 * (1 - c) / t4 + 12 * (t - s) / t5;
  }
  return {f, f1 / (2 * t), (f2 - f1 / t) / (4 * t2)};
}
template <int N>
Jet<N> rotation_coefficient(int kind, const Jet<N>& t2) {
  const CoefficientValue c = rotation_coefficient(kind, t2.v);
  return chain(t2, c.f, c.d1, c.d2);
}

// ---- double helpers with Eigen types -------------------------------------

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}
inline Eigen::Quaterniond to_eigen(const Quat<double>& q) { return Eigen::Quaterniond(q.w, q.x, q.y, q.z); }
inline Eigen::Quaterniond quat_exp(const Eigen::Vector3d& psi) {
  return to_eigen(qexp<double>({psi.x(), psi.y(), psi.z()}));
}
inline Eigen::Vector3d quat_log(const Eigen::Quaterniond& q) {
  const V3<double> p = qlog<double>({q.w(), q.x(), q.y(), q.z()});
  return {p[0], p[1], p[2]};
}

}  // namespace stentsim::solver::beams
