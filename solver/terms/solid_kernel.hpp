#pragma once
// Residual and tangent of one total-Lagrangian solid element (Holzapfel 2000,
// ch. 8; Wriggers 2008, ch. 4): f_I = sum_qp B_I^T S w det J0,
// K_IJ = sum_qp (B_I^T D B_J + (g_I . S g_J) 1) w det J0, with g_I = dN_I/dX and
// the Voigt operator B of the Green-Lagrange strain. Local DOFs are node-major
// (3 I + k). Fixed-size throughout: no allocation inside the element loop.
#include <Eigen/Core>

#include "solver/fem/elements.hpp"
#include "solver/fem/kinematics.hpp"
#include "solver/materials/material.hpp"

namespace stentsim::solver {

template <class E>
struct SolidElement {
  static constexpr int kNodes = E::kNodes, kDofs = 3 * E::kNodes, kPoints = E::kRule.kPoints;
  using NodeMat = Eigen::Matrix<double, 3, kNodes>;
  using Vec = Eigen::Matrix<double, kDofs, 1>;
  using Mat = Eigen::Matrix<double, kDofs, kDofs>;

  /// Where a failure happened inside the element.
  struct Outcome {
    PointStatus status;
    int point = -1;   // quadrature point
    int corner = -1;  // or element node (E::kCornerXi order = the element's first nodes)
  };

  /// Material response at every quadrature point; the caller aggregates.
  struct PointState {
    Mat3 f;
    Vec6 stress;  // total S (hyperelastic + viscous)
    double weight;  // w det J0
  };

  /// B operator (6 x 3N) at one point.
  static void strain_operator(const Mat3& f, const Eigen::Matrix<double, kNodes, 3>& g,
                              Eigen::Matrix<double, 6, kDofs>& b) {
    for (int i = 0; i < kNodes; ++i)
      for (int k = 0; k < 3; ++k) {
        const int c = 3 * i + k;
        b(0, c) = f(k, 0) * g(i, 0);
        b(1, c) = f(k, 1) * g(i, 1);
        b(2, c) = f(k, 2) * g(i, 2);
        b(3, c) = f(k, 0) * g(i, 1) + f(k, 1) * g(i, 0);
        b(4, c) = f(k, 1) * g(i, 2) + f(k, 2) * g(i, 1);
        b(5, c) = f(k, 0) * g(i, 2) + f(k, 2) * g(i, 0);
      }
  }

  /// The first corner (of E::kCornerXi, for elements whose J varies enough to
  /// change sign away from the Gauss points: tet10) where J = det F <= 0, or -1.
  /// sign(J) = sign(det dx/dxi) * sign(det dX/dxi), so no inverse is needed.
  static int inverted_corner(const NodeMat& x_ref, const NodeMat& x_cur) {
    if constexpr (requires { E::kCornerXi; }) {
      for (int c = 0; c < static_cast<int>(E::kCornerXi.size()); ++c) {
        const auto sv = E::eval(E::kCornerXi[c]);
        const Mat3 j_cur = x_cur * sv.dn, j_ref = x_ref * sv.dn;
        if (!(j_cur.determinant() * j_ref.determinant() > 0.0)) return c;
      }
    }
    return -1;
  }

  /// Residual (internal force) and, if `k` is not null, tangent.
  /// `history` (kPoints entries, committed) and `trial` (kPoints entries,
  /// written) are used when the material has a viscous branch; `dt` is the step.
  static Outcome evaluate(const NodeMat& x_ref, const NodeMat& x_cur, const Material& mat, const Vec3* fiber_dirs,
                          const ViscousHistory* history, ViscousHistory* trial, double dt, Vec& r, Mat* k) {
    r.setZero();
    if (k) k->setZero();
    if (auto corner = inverted_corner(x_ref, x_cur); corner >= 0)
      return {PointStatus::fail("J = det F <= 0 (inverted element)"), -1, corner};
    Eigen::Matrix<double, kNodes, 3> g;
    Eigen::Matrix<double, 6, kDofs> b;
    Vec6 s;
    Mat6 d;
    for (int q = 0; q < kPoints; ++q) {
      const auto sv = E::eval(E::kRule.points[q]);
      double det = 0.0;
      if (!fem::reference_gradients<kNodes>(x_ref, sv.dn, g, det))
        return {PointStatus::fail("degenerate or inverted reference element"), q};
      const double w = E::kRule.weights[q] * det;
      const Mat3 f = fem::deformation_gradient<kNodes>(x_cur, g);
      // The materials see C only, whose determinant J^2 hides the sign of J:
      // an inverted point (J = det F <= 0) is caught here (DESIGN.md §7).
      if (!(f.determinant() > 0.0)) return {PointStatus::fail("J = det F <= 0 (inverted element)"), q};
      const Mat3 c = f.transpose() * f;
      if (auto st = mat.elastic(c, fiber_dirs, s, k ? &d : nullptr); !st.ok) return {st, q};
      if (mat.viscous && history) {
        const Vec6 q_new = mat.viscous->update(history[q], s, dt);
        if (trial) trial[q] = {q_new, s};
        s += q_new;
        if (k) d *= 1.0 + mat.viscous->gain(dt);
      }
      strain_operator(f, g, b);
      r.noalias() += w * b.transpose() * s;
      if (k) {
        k->noalias() += w * b.transpose() * (d * b);
        const Mat3 sm = from_voigt_stress(s);
        const Eigen::Matrix<double, kNodes, kNodes> geo = w * g * sm * g.transpose();
        for (int i = 0; i < kNodes; ++i)
          for (int j = 0; j < kNodes; ++j)
            for (int a = 0; a < 3; ++a) (*k)(3 * i + a, 3 * j + a) += geo(i, j);
      }
    }
    return {PointStatus::good(), -1};
  }

  /// Volume-weighted means of Cauchy stress and Green-Lagrange strain (output);
  /// `point_cauchy` (optional, kPoints entries) receives the Cauchy stress at each quadrature point.
  static Outcome averages(const NodeMat& x_ref, const NodeMat& x_cur, const Material& mat, const Vec3* fiber_dirs,
                          const ViscousHistory* history, Mat3& cauchy, Mat3& strain, double& volume,
                          Mat3* point_cauchy = nullptr) {
    cauchy.setZero();
    strain.setZero();
    volume = 0.0;
    Eigen::Matrix<double, kNodes, 3> g;
    Vec6 s;
    for (int q = 0; q < kPoints; ++q) {
      const auto sv = E::eval(E::kRule.points[q]);
      double det = 0.0;
      if (!fem::reference_gradients<kNodes>(x_ref, sv.dn, g, det))
        return {PointStatus::fail("degenerate or inverted reference element"), q};
      const double w = E::kRule.weights[q] * det;
      const Mat3 f = fem::deformation_gradient<kNodes>(x_cur, g);
      if (!(f.determinant() > 0.0)) return {PointStatus::fail("J = det F <= 0 (inverted element)"), q};
      if (auto st = mat.elastic(f.transpose() * f, fiber_dirs, s, nullptr); !st.ok) return {st, q};
      if (mat.viscous && history) s += history[q].q;  // committed state: Q of the output step
      const Mat3 sigma = cauchy_from_pk2(f, from_voigt_stress(s));
      if (point_cauchy) point_cauchy[q] = sigma;
      cauchy += w * sigma;
      strain += w * fem::green_lagrange(f);
      volume += w;
    }
    cauchy /= volume;
    strain /= volume;
    return {PointStatus::good(), -1};
  }
};

}  // namespace stentsim::solver
