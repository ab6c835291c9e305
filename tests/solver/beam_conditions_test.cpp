// Loads and conditions on beams (issue 8): distributed line load, prescribed
// tip rotation, the "moves only along a direction" constraint; and the
// rotation algebra the element rests on.
#include "solver/beams/beam_loads.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/direction_constraint.hpp"
#include "solver/beams/rotation.hpp"
#include "tests/solver/beam_test_bodies.hpp"
#include "tests/solver/beam_test_system.hpp"

#include "common/error.hpp"

#include <gtest/gtest.h>

#include <numbers>

using namespace stentsim::solver;
using namespace stentsim::solver::beams;
using namespace stentsim::solver::beams::testing;

namespace {
constexpr double L = 10.0, E = 1e4, G = 5e3, I = 1.0 / 12;
BeamSection square() { return BeamSection::from_values(E, G, 1.0, 1.0, 1.0, I, I, 1.0 / 6); }
}  // namespace

TEST(BeamRotation, ExpLogRoundTripAndRightJacobian) {
  for (double angle : {0.0, 1e-12, 1e-6, 1e-3, 0.2, 1.0, 2.5, 3.1}) {
    const Eigen::Vector3d psi = angle * Eigen::Vector3d(0.36, -0.48, 0.8);
    EXPECT_LT((quat_log(quat_exp(psi)) - psi).norm(), 1e-15 + 1e-14 * angle) << angle;
    // matches Eigen's angle-axis
    if (angle > 0)
      EXPECT_LT((quat_exp(psi).toRotationMatrix() - Eigen::AngleAxisd(angle, psi.normalized()).toRotationMatrix()).norm(), 1e-14);
  }
  // Λ(s) = exp(S(ψ(s))): Λᵀ Λ' = S(J_r(ψ) ψ') against central differences.
  for (double scale : {1e-4, 0.5, 2.8}) {
    auto psi = [&](double s) { return Eigen::Vector3d(scale * std::cos(s), scale * std::sin(2 * s), 0.3 * scale * s); };
    auto dpsi = [&](double s) { return Eigen::Vector3d(-scale * std::sin(s), 2 * scale * std::cos(2 * s), 0.3 * scale); };
    const double s = 0.7, h = 1e-6;
    const Eigen::Matrix3d A = quat_exp(psi(s)).toRotationMatrix();
    const Eigen::Matrix3d dA = (quat_exp(psi(s + h)).toRotationMatrix() - quat_exp(psi(s - h)).toRotationMatrix()) / (2 * h);
    const Eigen::Matrix3d W = A.transpose() * dA;
    const Eigen::Vector3d k_fd(W(2, 1), W(0, 2), W(1, 0));
    const Eigen::Vector3d p = psi(s), dp = dpsi(s);
    const V3<double> k = right_jacobian_times<double>({p.x(), p.y(), p.z()}, {dp.x(), dp.y(), dp.z()});
    EXPECT_LT((Eigen::Vector3d(k[0], k[1], k[2]) - k_fd).norm(), 1e-8 * (1 + k_fd.norm())) << scale;
  }
}

TEST(BeamRotation, JetDerivativesOfLogMatchFiniteDifferences) {
  // Gradient and Hessian of |qlog(qexp2(h) ⊗ q)|² with respect to h, near and away from identity.
  for (double angle : {0.0, 1e-5, 1.3, 3.0}) {
    const Eigen::Quaterniond q = quat_exp(angle * Eigen::Vector3d(0.6, 0.0, 0.8));
    using J = Jet<3>;
    const V3<J> h{J::variable(0, 0), J::variable(0, 1), J::variable(0, 2)};
    const V3<J> v = qlog(qmul(qexp_second_order(h), qconst<J>(q)));
    const J f = dot(v, v) + v[0];
    auto fval = [&](const Eigen::Vector3d& d) {
      const Eigen::Vector3d w = quat_log(quat_exp(d) * q);
      return w.squaredNorm() + w.x();
    };
    const double e = 1e-4;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d di = e * Eigen::Vector3d::Unit(i);
      EXPECT_NEAR(f.g[i], (fval(di) - fval(-di)) / (2 * e), 1e-7) << angle;
      for (int j = 0; j < 3; ++j) {
        const Eigen::Vector3d dj = e * Eigen::Vector3d::Unit(j);
        // symmetric part of the second derivative along exp(S(a e_i + b e_j))
        const double fd = (fval(di + dj) - fval(di - dj) - fval(-di + dj) + fval(-di - dj)) / (4 * e * e);
        EXPECT_NEAR(f.hessian()(i, j), fd, 1e-5) << angle << " " << i << j;
      }
    }
  }
}

TEST(BeamConditions, UniformLineLoadSmallDeflection) {
  // Timoshenko cantilever under a small uniform load q e_z:
  // w(L) = qL⁴/(8EI) + qL²/(2 G A_s), in the linear range.
  const double q = 1e-4;
  for (BeamInterpolation kind : {BeamInterpolation::hermite3, BeamInterpolation::lagrange2}) {
    for (int n : {4, 8, 16, 32}) {
    BeamBodyDefinition def = curve_body(straight_x(), L, n, square(), kind);
    GlobalDof ndof = 0;
    auto dofs = number_beam_dofs(def, 0, &ndof);
    // Clamped = position and rotation fixed. The Hermite tangent stays free:
    // r'(0) = Λ(0)(E₁ + Γ(0)) carries the root shear strain, and fixing it
    // would impose Γ(0) = 0 (an O(h) error under shear, seen here otherwise).
    dofs[0].pos = dofs[0].rot = {-1, -1, -1};
    BeamTerm beam("b", def, dofs);
    BeamLineLoadTerm load("q", beam, Eigen::Vector3d(0, 0, q), nullptr);
    TestSystem sys(ndof);
    sys.terms = {&beam, &load};
    sys.solve(1.0, 1e-14);
    const double w = beam.position(sys.u, n).z();
    const double exact = q * L * L * L * L / (8 * E * I) + q * L * L / (2 * G * 1.0);
    std::printf("%s: tip deflection %.10e, Timoshenko %.10e\n", kind == BeamInterpolation::hermite3 ? "hermite" : "lagrange", w,
                exact);
    std::printf("  N=%d rel. error %.3e\n", n, w / exact - 1);
    EXPECT_NEAR(w / exact, 1.0, 1e-8) << n;
    }
  }
}

TEST(BeamConditions, PrescribedTipRotationBendsIntoAnArc) {
  // Tip triad prescribed to turn by φ about e_z, tip position free: uniform
  // curvature φ/L, the tip on the arc (L/φ) (sin φ, 1 − cos φ, 0).
  const double phi = 2.0;
  const int n = 16;
  BeamBodyDefinition def = curve_body(straight_x(), L, n, square());
  GlobalDof ndof = 0;
  auto dofs = number_beam_dofs(def, 0, &ndof);
  dofs[0].pos = dofs[0].rot = dofs[0].tan = {-1, -1, -1};
  dofs[n].rot = {-1, -1, -1};  // rotation Dirichlet at the tip
  BeamTerm beam("b", def, dofs);
  TestSystem sys(ndof);
  sys.terms = {&beam};
  for (int step = 1; step <= 5; ++step) {
    beam.set_rotation(n, quat_exp(Eigen::Vector3d(0, 0, phi * step / 5)));
    sys.solve(step / 5.0, 1e-12 * L);
  }
  const Eigen::Vector3d exact = L / phi * Eigen::Vector3d(std::sin(phi), 1 - std::cos(phi), 0);
  const double err = (beam.position(sys.u, n) - exact).norm();
  std::printf("prescribed rotation: tip error %.3e\n", err);
  EXPECT_LT(err, 1e-5 * L);
  // the curvature is uniform: every quadrature point has Ω₃ = φ/L, N = 0
  for (std::size_t e = 0; e < def.elements.size(); ++e)
    for (const SectionState& s : beam.section_states(sys.u, e)) {
      EXPECT_NEAR(s.Omega.z(), phi / L, 1e-5);
      EXPECT_NEAR(s.F.x(), 0.0, 1e-4 * 1e4 * I * phi / L);  // ≪ M/L
    }
}

TEST(BeamConditions, PrescribedPositionTangentAndRotation) {
  // Non-homogeneous Dirichlet on all tip DOFs (position, tangent, rotation)
  // taken from the circular arc of curvature φ/L: the interior follows the arc.
  const double phi = 1.5;
  const int n = 16;
  BeamBodyDefinition def = curve_body(straight_x(), L, n, square());
  GlobalDof ndof = 0;
  auto dofs = number_beam_dofs(def, 0, &ndof);
  dofs[0].pos = dofs[0].rot = dofs[0].tan = {-1, -1, -1};
  const BeamNodeDofs tip = dofs[n];
  dofs[n].rot = {-1, -1, -1};
  BeamTerm beam("b", def, dofs);
  TestSystem sys(ndof);
  sys.terms = {&beam};
  for (int i = 0; i < 3; ++i) sys.fixed.push_back(tip.pos[i]), sys.fixed.push_back(tip.tan[i]);
  for (int step = 1; step <= 5; ++step) {
    const double a = phi * step / 5;
    const Eigen::Vector3d r = L / a * Eigen::Vector3d(std::sin(a), 1 - std::cos(a), 0), t(std::cos(a), std::sin(a), 0);
    for (int i = 0; i < 3; ++i) {
      sys.u[tip.pos[i]] = r[i] - def.nodes[n].position[i];
      sys.u[tip.tan[i]] = t[i] - (i == 0 ? 1.0 : 0.0);
    }
    beam.set_rotation(n, quat_exp(Eigen::Vector3d(0, 0, a)));
    sys.solve(step / 5.0, 1e-12 * L);
  }
  double err = 0.0;
  for (int k = 0; k <= n; ++k) {
    const double s = L * k / n;
    const Eigen::Vector3d exact = L / phi * Eigen::Vector3d(std::sin(phi * s / L), 1 - std::cos(phi * s / L), 0);
    err = std::max(err, (beam.position(sys.u, k) - exact).norm());
  }
  std::printf("prescribed position/tangent/rotation: max nodal error on the arc %.3e\n", err);
  EXPECT_LT(err, 1e-5 * L);
  EXPECT_NEAR(beam.tangent(sys.u, n).x(), std::cos(phi), 1e-15);
}

TEST(BeamConditions, NodeMovesOnlyAlongDirection) {
  // Cantilever with its tip constrained to the line X_tip + α d, loaded
  // off that line: the tip stays on it and the reaction is normal to d.
  const int n = 8;
  BeamBodyDefinition def = curve_body(straight_x(), L, n, square());
  GlobalDof ndof = 0;
  auto dofs = number_beam_dofs(def, 0, &ndof);
  dofs[0].pos = dofs[0].rot = dofs[0].tan = {-1, -1, -1};
  const GlobalDof lam = ndof;
  ndof += 2;
  BeamTerm beam("b", def, dofs);
  const Eigen::Vector3d d = Eigen::Vector3d(-1, 1, 0.5).normalized();
  DirectionConstraintTerm c("fix", dofs[n].pos, d, {lam, lam + 1});
  const Eigen::Vector3d F(25.0, 150.0, -100.0);
  NodalLoadTerm f("f", dofs[n].pos, F, [](double t) { return t; });
  TestSystem sys(ndof);
  sys.terms = {&beam, &f, &c};
  for (int step = 1; step <= 5; ++step) sys.solve(step / 5.0, 1e-12 * L);
  const Eigen::Vector3d u = beam.position(sys.u, n) - def.nodes[n].position;
  const Eigen::Vector3d normal_part = u - u.dot(d) * d;
  std::printf("direction constraint: tip moved %.4f along d, %.2e off the line; reaction·d %.2e\n", u.dot(d),
              normal_part.norm(), c.reaction(sys.u).dot(d));
  EXPECT_GT(std::abs(u.dot(d)), 0.05);  // it did move
  EXPECT_LT(normal_part.norm(), 1e-12);
  EXPECT_LT(std::abs(c.reaction(sys.u).dot(d)), 1e-9 * F.norm());
  EXPECT_GT(c.reaction(sys.u).norm(), 0.1 * F.norm());  // and the constraint carried load
}

TEST(BeamConditions, FixedAlongDirectionKeepsTheNodeInItsPlane) {
  // "Fixed along d" (the stent's axial fixation): one multiplier, d·u = 0; the
  // tip moves freely in the plane normal to d and the reaction is along d.
  const int n = 8;
  BeamBodyDefinition def = curve_body(straight_x(), L, n, square());
  GlobalDof ndof = 0;
  auto dofs = number_beam_dofs(def, 0, &ndof);
  dofs[0].pos = dofs[0].rot = dofs[0].tan = {-1, -1, -1};
  const GlobalDof lam = ndof;
  ndof += 1;
  BeamTerm beam("b", def, dofs);
  const Eigen::Vector3d d = Eigen::Vector3d(-1, 1, 0.5).normalized();
  DirectionConstraintTerm c("fix", dofs[n].pos, d, lam);
  EXPECT_EQ(c.kind(), DirectionConstraintTerm::Kind::normal);
  const Eigen::Vector3d F(0.25, 1.5, -1.0);  // tip deflection ~ F L³/(3EI) ≈ 0.7 (free in the plane)
  NodalLoadTerm f("f", dofs[n].pos, F, [](double t) { return t; });
  TestSystem sys(ndof);
  sys.terms = {&beam, &f, &c};
  for (int step = 1; step <= 5; ++step) sys.solve(step / 5.0, 1e-12 * L);
  const Eigen::Vector3d u = beam.position(sys.u, n) - def.nodes[n].position;
  const Eigen::Vector3d reaction = c.reaction(sys.u);
  std::printf("fixed along d: d·u %.2e, in-plane move %.4f; reaction off d %.2e\n", u.dot(d), (u - u.dot(d) * d).norm(),
              (reaction - reaction.dot(d) * d).norm());
  EXPECT_LT(std::abs(u.dot(d)), 1e-12);
  EXPECT_GT((u - u.dot(d) * d).norm(), 0.05);  // it did move
  EXPECT_LT((reaction - reaction.dot(d) * d).norm(), 1e-12 * F.norm());
  EXPECT_GT(std::abs(reaction.dot(d)), 0.1 * F.norm());  // and the constraint carried load
}

TEST(BeamConditions, BadInputIsReported) {
  BeamBodyDefinition def = curve_body(straight_x(), L, 2, square());
  GlobalDof ndof = 0;
  auto dofs = number_beam_dofs(def, 0, &ndof);
  def.elements[1].mid = 99;
  EXPECT_THROW(BeamTerm("bad", def, dofs), stentsim::InputError);
  BeamBodyDefinition def2 = curve_body(straight_x(), L, 2, BeamSection::from_values(E, G, 0.0, 1, 1, I, I, 1));
  EXPECT_THROW(BeamTerm("bad", def2, dofs), stentsim::InputError);
  EXPECT_THROW(DirectionConstraintTerm("c", {0, 1, 2}, Eigen::Vector3d::Zero(), {3, 4}), stentsim::InputError);
}
