#pragma once
// Total-Lagrangian kinematics at a quadrature point: reference gradients of
// the shape functions, deformation gradient F = x_I (x) dN_I/dX, and strain
// measures (Holzapfel 2000, ch. 2).
#include <Eigen/Core>
#include <Eigen/LU>

#include "solver/fem/tensor.hpp"

namespace stentsim::solver::fem {

/// dN/dX (N x 3) and det(dX/dxi) from nodal reference coordinates (3 x N)
/// and reference gradients dN/dxi (N x 3). Returns false for a degenerate
/// or inverted reference element.
template <int N>
inline bool reference_gradients(const Eigen::Matrix<double, 3, N>& x_ref, const Eigen::Matrix<double, N, 3>& dn_dxi,
                                Eigen::Matrix<double, N, 3>& dn_dx, double& det) {
  const Mat3 j = x_ref * dn_dxi;  // dX/dxi
  det = j.determinant();
  if (!(det > 0.0)) return false;
  dn_dx = dn_dxi * j.inverse();
  return true;
}

/// F = sum_I x_I (x) dN_I/dX with current nodal positions (3 x N).
template <int N>
inline Mat3 deformation_gradient(const Eigen::Matrix<double, 3, N>& x_cur, const Eigen::Matrix<double, N, 3>& dn_dx) {
  return x_cur * dn_dx;
}

/// Green-Lagrange strain E = (C - I) / 2.
inline Mat3 green_lagrange(const Mat3& f) { return 0.5 * (f.transpose() * f - Mat3::Identity()); }

}  // namespace stentsim::solver::fem
