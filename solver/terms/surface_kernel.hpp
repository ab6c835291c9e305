#pragma once
// Surface element kernels on quad4, tri3, tri6 (local DOFs node-major).
//
// Follower pressure p on the current surface, pushing against the outward
// normal: traction t = -p n da = -p (x,xi x x,eta) dxi deta (Nanson,
// n da = J F^-T N dA). Residual R = f_int - f_ext gives
//   R_I = p sum_qp w N_I (x,xi x x,eta),
//   dR_I/dx_J = p sum_qp w N_I (dN_J/deta [x,xi]_x - dN_J/dxi [x,eta]_x),
// with [a]_x v = a x v: the consistent, non-symmetric linearization.
//
// Omnidirectional Robin springs of stiffness k per reference area:
//   R_I = k sum_qp w |X,xi x X,eta| N_I N_J u_J  (constant, symmetric tangent).
#include <Eigen/Core>

#include "solver/fem/elements.hpp"
#include "solver/fem/tensor.hpp"

namespace stentsim::solver {

inline Mat3 skew(const Vec3& a) {
  Mat3 s;
  s << 0, -a(2), a(1), a(2), 0, -a(0), -a(1), a(0), 0;
  return s;
}

template <class S>
struct SurfaceElement {
  static constexpr int kNodes = S::kNodes, kDofs = 3 * S::kNodes;
  using NodeMat = Eigen::Matrix<double, 3, kNodes>;
  using Vec = Eigen::Matrix<double, kDofs, 1>;
  using Mat = Eigen::Matrix<double, kDofs, kDofs>;

  static void pressure(const NodeMat& x_cur, double p, Vec& r, Mat* k) {
    r.setZero();
    if (k) k->setZero();
    for (int q = 0; q < S::kRule.kPoints; ++q) {
      const auto sv = S::eval(S::kRule.points[q]);
      const double w = S::kRule.weights[q] * p;
      const Vec3 a1 = x_cur * sv.dn.col(0), a2 = x_cur * sv.dn.col(1);
      const Vec3 n = a1.cross(a2);
      for (int i = 0; i < kNodes; ++i) r.template segment<3>(3 * i) += w * sv.n(i) * n;
      if (!k) continue;
      const Mat3 s1 = skew(a1), s2 = skew(a2);
      for (int j = 0; j < kNodes; ++j) {
        const Mat3 dn_j = sv.dn(j, 1) * s1 - sv.dn(j, 0) * s2;
        for (int i = 0; i < kNodes; ++i) k->template block<3, 3>(3 * i, 3 * j) += w * sv.n(i) * dn_j;
      }
    }
  }

  static void spring(const NodeMat& x_ref, const NodeMat& disp, double stiffness, Vec& r, Mat& k) {
    k.setZero();
    for (int q = 0; q < S::kRule.kPoints; ++q) {
      const auto sv = S::eval(S::kRule.points[q]);
      const double da = (x_ref * sv.dn.col(0)).cross(x_ref * sv.dn.col(1)).norm();
      const double w = S::kRule.weights[q] * da * stiffness;
      for (int i = 0; i < kNodes; ++i)
        for (int j = 0; j < kNodes; ++j) k.template block<3, 3>(3 * i, 3 * j).diagonal().array() += w * sv.n(i) * sv.n(j);
    }
    Vec u;
    for (int i = 0; i < kNodes; ++i) u.template segment<3>(3 * i) = disp.col(i);
    r = k * u;
  }

  /// Current area (for output and checks).
  static double area(const NodeMat& x) {
    double a = 0.0;
    for (int q = 0; q < S::kRule.kPoints; ++q) {
      const auto sv = S::eval(S::kRule.points[q]);
      a += S::kRule.weights[q] * (x * sv.dn.col(0)).cross(x * sv.dn.col(1)).norm();
    }
    return a;
  }
};

}  // namespace stentsim::solver
