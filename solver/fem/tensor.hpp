#pragma once
// Small fixed-size tensor types and Voigt helpers used by every material and
// element kernel. Voigt order: 11, 22, 33, 12, 23, 13; strains carry
// engineering shears (2 E12), stresses do not, so that S : dE = S_v . dE_v.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <array>
#include <cmath>

namespace stentsim::solver {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

/// Index pairs (i, j) of the Voigt components.
inline constexpr std::array<std::array<int, 2>, 6> kVoigtPairs{{{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}}};

/// Symmetric tensor -> Voigt stress vector.
inline Vec6 to_voigt_stress(const Mat3& s) {
  Vec6 v;
  for (int a = 0; a < 6; ++a) v(a) = s(kVoigtPairs[a][0], kVoigtPairs[a][1]);
  return v;
}

/// Voigt stress vector -> symmetric tensor.
inline Mat3 from_voigt_stress(const Vec6& v) {
  Mat3 s;
  s << v(0), v(3), v(5), v(3), v(1), v(4), v(5), v(4), v(2);
  return s;
}

/// Symmetric strain tensor -> Voigt strain (engineering shears).
inline Vec6 to_voigt_strain(const Mat3& e) {
  Vec6 v;
  for (int a = 0; a < 6; ++a) v(a) = (a < 3 ? 1.0 : 2.0) * e(kVoigtPairs[a][0], kVoigtPairs[a][1]);
  return v;
}

/// D += alpha * (A (x) B) in Voigt form: D(a,b) = A_ij B_kl.
inline void add_outer(Mat6& d, double alpha, const Mat3& a, const Mat3& b) {
  for (int p = 0; p < 6; ++p)
    for (int q = 0; q < 6; ++q)
      d(p, q) += alpha * a(kVoigtPairs[p][0], kVoigtPairs[p][1]) * b(kVoigtPairs[q][0], kVoigtPairs[q][1]);
}

/// D += alpha * (A (.) B), (A (.) B)_ijkl = 1/2 (A_ik B_jl + A_il B_jk): the
/// derivative of a product like C^-1 with respect to C (Holzapfel 2000, 6.1).
inline void add_symmetric_product(Mat6& d, double alpha, const Mat3& a, const Mat3& b) {
  for (int p = 0; p < 6; ++p) {
    const int i = kVoigtPairs[p][0], j = kVoigtPairs[p][1];
    for (int q = 0; q < 6; ++q) {
      const int k = kVoigtPairs[q][0], l = kVoigtPairs[q][1];
      d(p, q) += alpha * 0.5 * (a(i, k) * b(j, l) + a(i, l) * b(j, k));
    }
  }
}

/// Cauchy stress from the second Piola-Kirchhoff stress: sigma = F S F^T / J.
inline Mat3 cauchy_from_pk2(const Mat3& f, const Mat3& s) { return f * s * f.transpose() / f.determinant(); }

/// Von Mises equivalent of a Cauchy stress.
inline double von_mises(const Mat3& sigma) {
  const Mat3 dev = sigma - sigma.trace() / 3.0 * Mat3::Identity();
  return std::sqrt(1.5 * dev.cwiseProduct(dev).sum());
}

}  // namespace stentsim::solver
