#pragma once
// Reference solutions of the static Simo–Reissner rod under a dead tip force
// by shooting (issue 8; the error study's `beam_shooting` reference, issue 11):
// integrate
//   r' = Λ(E₁ + C_F⁻¹ Λᵀ n),  Λ' = Λ S(C_M⁻¹ Λᵀ m + K₀),  m' = −r' × n,  n ≡ F,
// from the clamped root with an unknown root moment m(0), and solve m(L) = 0
// by Newton (finite-difference Jacobian). Integration: classical RK4 on
// (r, q, m) with the quaternion ODE q' = ½ q ⊗ (0, κ), renormalized each step.
// Independent of the finite-element code on purpose: the solver's beam tests
// (tests/solver/beam_bend45_test.cpp, beam_resultant_output_test.cpp, beam_scene_test.cpp)
// and the error study measure against the same numbers.
//
// Header-only, like tube_reference.hpp, so that the solver tests use it
// without linking the workflows.
#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace stentsim::study::reference {

struct RodProblem {
  double length = 0.0;
  Eigen::Vector3d CF, CM;                 // section stiffnesses (EA, GA2, GA3), (GI_T, EI2, EI3)
  Eigen::Vector3d K0;                     // constant reference curvature (material frame)
  Eigen::Vector3d r0 = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q0 = Eigen::Quaterniond::Identity();  // root triad (columns d1 = tangent, d2, d3)
  int steps = 4000;
};

struct RodState {
  Eigen::Vector3d r;
  Eigen::Vector4d q;  // (w, x, y, z)
  Eigen::Vector3d m;
};

inline RodState rod_rhs(const RodProblem& p, const Eigen::Vector3d& F, const RodState& y) {
  const Eigen::Quaterniond q(y.q[0], y.q[1], y.q[2], y.q[3]);
  const Eigen::Matrix3d L = q.normalized().toRotationMatrix();
  RodState d;
  d.r = L * (Eigen::Vector3d::UnitX() + (L.transpose() * F).cwiseQuotient(p.CF));
  const Eigen::Vector3d k = (L.transpose() * y.m).cwiseQuotient(p.CM) + p.K0;
  const Eigen::Quaterniond dq = q * Eigen::Quaterniond(0.0, k.x(), k.y(), k.z());
  d.q = 0.5 * Eigen::Vector4d(dq.w(), dq.x(), dq.y(), dq.z());
  d.m = -d.r.cross(F);
  return d;
}

/// Integrates from s = 0 to L with the root moment m0; returns the end state.
inline RodState rod_integrate(const RodProblem& p, const Eigen::Vector3d& F, const Eigen::Vector3d& m0) {
  RodState y{p.r0, Eigen::Vector4d(p.q0.w(), p.q0.x(), p.q0.y(), p.q0.z()), m0};
  const double h = p.length / p.steps;
  auto axpy = [](const RodState& a, double c, const RodState& b) {
    return RodState{a.r + c * b.r, a.q + c * b.q, a.m + c * b.m};
  };
  for (int i = 0; i < p.steps; ++i) {
    const RodState k1 = rod_rhs(p, F, y);
    const RodState k2 = rod_rhs(p, F, axpy(y, h / 2, k1));
    const RodState k3 = rod_rhs(p, F, axpy(y, h / 2, k2));
    const RodState k4 = rod_rhs(p, F, axpy(y, h, k3));
    y.r += h / 6 * (k1.r + 2 * k2.r + 2 * k3.r + k4.r);
    y.q += h / 6 * (k1.q + 2 * k2.q + 2 * k3.q + k4.q);
    y.m += h / 6 * (k1.m + 2 * k2.m + 2 * k3.m + k4.m);
    y.q.normalize();
  }
  return y;
}

/// Solves m(L) = 0 for the root moment, starting from `m0` (updated); returns the tip state.
inline RodState rod_shoot(const RodProblem& p, const Eigen::Vector3d& F, Eigen::Vector3d& m0) {
  const double scale = F.norm() * p.length + 1.0;
  for (int it = 0; it < 50; ++it) {
    const RodState end = rod_integrate(p, F, m0);
    if (end.m.norm() < 1e-11 * scale) return end;
    Eigen::Matrix3d J;
    const double h = 1e-6 * scale;
    for (int j = 0; j < 3; ++j) {
      Eigen::Vector3d dm = Eigen::Vector3d::Zero();
      dm[j] = h;
      J.col(j) = (rod_integrate(p, F, m0 + dm).m - rod_integrate(p, F, m0 - dm).m) / (2 * h);
    }
    m0 -= J.partialPivLu().solve(end.m);
  }
  throw std::runtime_error("rod shooting did not converge");
}

/// The tip state under the dead force F reached by load continuation from 0
/// in `increments` equal steps (Newton's start is the previous root moment):
/// large deflections need it, as the solver's own load stepping does.
inline RodState rod_tip_under_force(const RodProblem& p, const Eigen::Vector3d& F, int increments) {
  Eigen::Vector3d m0 = Eigen::Vector3d::Zero();
  if (F.norm() == 0.0) return rod_integrate(p, F, m0);
  RodState end{};
  for (int i = 1; i <= std::max(1, increments); ++i) end = rod_shoot(p, F * (static_cast<double>(i) / std::max(1, increments)), m0);
  return end;
}

}  // namespace stentsim::study::reference
