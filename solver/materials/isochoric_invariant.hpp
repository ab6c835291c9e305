#pragma once
// Stress and tangent of a summand psi(Ibar) of an isochoric invariant
// Ibar = J^(-2/3) I, I = A : C (A = 1 gives Ibar1, A = M (x) M gives Ibar4;
// Holzapfel, Nonlinear Solid Mechanics, Sec. 6.4). With D = dIbar/dC:
//   D  = J^(-2/3) (A - I/3 C^-1)
//   S  = 2 psi' D
//   CC = 2 dS/dC = 4 psi'' D (x) D
//        + 4 psi' J^(-2/3) [ -1/3 (A (x) C^-1 + C^-1 (x) A) + I/9 C^-1 (x) C^-1 + I/3 C^-1 (.) C^-1 ]
// where (.) is the symmetrized product (C^-1 (.) C^-1)_ijkl = (Cik Cjl + Cil Cjk)/2.
#include <cmath>

#include "solver/fem/tensor.hpp"

namespace stentsim::solver {

/// J^(-2/3) I, the isochoric part of the invariant I = A : C.
inline double isochoric_invariant(const Mat3& a, const Mat3& cauchy_green, double j) {
  return std::pow(j, -2.0 / 3.0) * (a.cwiseProduct(cauchy_green)).sum();
}

/// Adds S and CC (when `tangent` is not null) of psi(Ibar) with psi' = d1, psi'' = d2.
inline void add_isochoric_invariant(const Mat3& a, const Mat3& cauchy_green, const Mat3& c_inv, double j, double d1,
                                    double d2, Vec6& stress, Mat6* tangent) {
  const double jm = std::pow(j, -2.0 / 3.0);
  const double inv = (a.cwiseProduct(cauchy_green)).sum();
  const Mat3 d = jm * (a - inv / 3.0 * c_inv);
  stress += 2.0 * d1 * to_voigt_stress(d);
  if (!tangent) return;
  if (d2 != 0.0) add_outer(*tangent, 4.0 * d2, d, d);
  const double g = 4.0 * d1 * jm;
  add_outer(*tangent, -g / 3.0, a, c_inv);
  add_outer(*tangent, -g / 3.0, c_inv, a);
  add_outer(*tangent, g * inv / 9.0, c_inv, c_inv);
  add_symmetric_product(*tangent, g * inv / 3.0, c_inv, c_inv);
}

}  // namespace stentsim::solver
