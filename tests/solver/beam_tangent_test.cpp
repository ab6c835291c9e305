// Finite-difference checks of the beam residual and tangent (issue 8):
// rotations perturbed multiplicatively with the update's own convention,
// Λ <- exp(S(h e_i)) Λ, at random deformed states with rotations beyond 90°.
#include "solver/beams/beam_loads.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/direction_constraint.hpp"
#include "solver/beams/rotation.hpp"
#include "tests/solver/beam_test_bodies.hpp"
#include "tests/solver/beam_test_system.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace stentsim::solver;
using namespace stentsim::solver::beams;
using namespace stentsim::solver::beams::testing;

namespace {

Eigen::Vector3d random_unit(std::mt19937& g) {
  std::normal_distribution<double> n;
  return Eigen::Vector3d(n(g), n(g), n(g)).normalized();
}

/// Random large deformation: every triad rotated by a common 2.5 rad rotation
/// and its own random rotation of up to `spread` rad; positions and tangents
/// displaced by up to `amp`·(element length).
void randomize(BeamTerm& beam, Eigen::VectorXd& u, unsigned seed, double spread = 0.9, double amp = 0.3) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  const double le = beam.reference(0).length;
  for (long i = 0; i < u.size(); ++i) u[i] = amp * le * uni(g);
  const Eigen::Quaterniond big = quat_exp(2.5 * random_unit(g));
  for (std::size_t n = 0; n < beam.body().nodes.size(); ++n) {
    const Eigen::Quaterniond own = quat_exp(spread * std::abs(uni(g)) * random_unit(g));
    beam.set_rotation(static_cast<int>(n), own * big * beam.body().nodes[n].triad);
  }
}

struct FdResult {
  double tangent_error = 0.0;   // |K_fd − K|_F / |K|_F
  double residual_error = 0.0;  // |R − ∇Π|/|R| over the beam's DOFs
};

FdResult fd_check(BeamTerm& beam, TestSystem& sys, double h) {
  const DenseAssembler base = sys.assemble(1.0);
  const long n = sys.u.size();
  Eigen::MatrixXd Kfd(n, n);
  Eigen::VectorXd gfd(n);
  const Eigen::VectorXd u0 = sys.u;
  for (long j = 0; j < n; ++j) {
    Eigen::VectorXd du = Eigen::VectorXd::Zero(n);
    du[j] = h;
    sys.u = u0 + du;
    beam.trial(du);
    const DenseAssembler p = sys.assemble(1.0);
    const double Ep = beam.energy(sys.u);
    sys.u = u0 - du;
    beam.trial(-du);
    const DenseAssembler m = sys.assemble(1.0);
    const double Em = beam.energy(sys.u);
    Kfd.col(j) = (p.R - m.R) / (2 * h);
    gfd[j] = (Ep - Em) / (2 * h);
  }
  sys.u = u0;
  beam.trial(Eigen::VectorXd::Zero(n));
  FdResult r;
  r.tangent_error = (Kfd - base.K).norm() / base.K.norm();
  r.residual_error = (gfd - base.R).norm() / base.R.norm();
  return r;
}

BeamSection test_section() { return BeamSection::from_values(1e3, 4e2, 1.0, 0.8, 0.7, 0.1, 0.15, 0.2); }

}  // namespace

TEST(BeamTangent, HermiteSingleElementRandomStates) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    BeamBodyDefinition def = curve_body(helix(2.0, 1.0), 3.0, 1, test_section());
    GlobalDof n = 0;
    auto dofs = number_beam_dofs(def, 0, &n);
    BeamTerm beam("b", def, dofs);
    TestSystem sys(n);
    sys.terms = {&beam};
    randomize(beam, sys.u, seed);
    // the state really rotates beyond 90°
    EXPECT_GT(quat_log(beam.rotation(0) * def.nodes[0].triad.conjugate()).norm(), std::numbers::pi / 2);
    const FdResult r = fd_check(beam, sys, 1e-5);
    RecordProperty("tangent_error_seed" + std::to_string(seed), std::to_string(r.tangent_error));
    std::printf("hermite seed %u: FD tangent rel. error %.3e, residual vs energy gradient %.3e\n", seed,
                r.tangent_error, r.residual_error);
    EXPECT_LT(r.tangent_error, 1e-6);
    EXPECT_LT(r.residual_error, 1e-6);
  }
}

TEST(BeamTangent, HermiteBodyWithLoadsAndConstraint) {
  BeamBodyDefinition def = curve_body(helix(2.0, 1.0), 6.0, 3, test_section(), BeamInterpolation::hermite3, 5);
  GlobalDof n = 0;
  auto dofs = number_beam_dofs(def, 0, &n);
  const GlobalDof lam = n;
  n += 2;
  BeamTerm beam("b", def, dofs);
  BeamLineLoadTerm q("q", beam, Eigen::Vector3d(0.1, -0.2, 0.3), nullptr);
  NodalLoadTerm f("f", dofs[3].pos, Eigen::Vector3d(1, 2, 3), nullptr);
  NodalLoadTerm m("m", dofs[3].rot, Eigen::Vector3d(-1, 0.5, 2), nullptr);
  DirectionConstraintTerm c("c", dofs[2].pos, Eigen::Vector3d(1, 1, 0), {lam, lam + 1});
  n += 1;
  DirectionConstraintTerm c2("c2", dofs[4].pos, Eigen::Vector3d(0.3, -1, 2), lam + 2);  // fixed along d
  TestSystem sys(n);
  sys.terms = {&beam, &q, &f, &m, &c, &c2};
  randomize(beam, sys.u, 42);
  const FdResult r = fd_check(beam, sys, 1e-5);
  std::printf("hermite 3 elements + loads: FD tangent rel. error %.3e\n", r.tangent_error);
  EXPECT_LT(r.tangent_error, 1e-6);
}

TEST(BeamTangent, HermiteNearIdentityAndReference) {
  // At the reference (all local rotation vectors zero: the series branches)
  // and slightly off it, the tangent must still match.
  BeamBodyDefinition def = curve_body(straight_x(), 2.0, 2, test_section());
  GlobalDof n = 0;
  auto dofs = number_beam_dofs(def, 0, &n);
  BeamTerm beam("b", def, dofs);
  TestSystem sys(n);
  sys.terms = {&beam};
  sys.u.setZero();
  for (int i = 0; i < n; ++i) sys.u[i] = 1e-3 * std::sin(1.0 + i);
  const FdResult r = fd_check(beam, sys, 1e-6);
  std::printf("hermite near reference: FD tangent rel. error %.3e\n", r.tangent_error);
  EXPECT_LT(r.tangent_error, 1e-6);
}

TEST(BeamTangent, LagrangeRandomStates) {
  for (unsigned seed = 7; seed <= 9; ++seed) {
    BeamBodyDefinition def = curve_body(helix(2.0, 1.0), 3.0, 2, test_section(), BeamInterpolation::lagrange2);
    GlobalDof n = 0;
    auto dofs = number_beam_dofs(def, 0, &n);
    EXPECT_EQ(n, 3 * 6);
    BeamTerm beam("b", def, dofs);
    TestSystem sys(n);
    sys.terms = {&beam};
    randomize(beam, sys.u, seed);
    const FdResult r = fd_check(beam, sys, 1e-5);
    std::printf("lagrange seed %u: FD tangent rel. error %.3e, residual vs energy gradient %.3e\n", seed,
                r.tangent_error, r.residual_error);
    EXPECT_LT(r.tangent_error, 1e-6);
    EXPECT_LT(r.residual_error, 1e-6);
  }
}

TEST(BeamTangent, DofCounts) {
  BeamBodyDefinition def = curve_body(straight_x(), 1.0, 3, test_section());
  EXPECT_EQ(beam_nodal_dof_count(def), 4 * 9 + 3 * 3);
  GlobalDof n = 0;
  number_beam_dofs(def, 10, &n);
  EXPECT_EQ(n, 10 + 4 * 9 + 3 * 3);
}

TEST(BeamTangent, ReferenceStiffnessHasExactlySixRigidModes) {
  // Stability of the default quadrature: a free element at its (curved)
  // reference has 6 zero-energy modes (rigid motions) and no spurious ones.
  for (BeamInterpolation kind : {BeamInterpolation::hermite3, BeamInterpolation::lagrange2}) {
    for (int gp : {0, 2}) {
      if (kind == BeamInterpolation::lagrange2 && gp == 2) continue;
      BeamBodyDefinition def = curve_body(helix(2.0, 1.0), 1.0, 1, test_section(), kind, gp);
      GlobalDof n = 0;
      BeamTerm beam("b", def, number_beam_dofs(def, 0, &n));
      TestSystem sys(n);
      sys.terms = {&beam};
      const DenseAssembler a = sys.assemble(0.0);
      const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a.K).eigenvalues();
      int zero = 0;
      for (long i = 0; i < ev.size(); ++i) zero += std::abs(ev[i]) < 1e-9 * ev.maxCoeff();
      std::printf("%s, %s Gauss points: %d zero-energy modes of %ld\n",
                  kind == BeamInterpolation::hermite3 ? "hermite" : "lagrange", gp ? "2" : "default", zero, ev.size());
      if (gp == 0) {
        EXPECT_EQ(zero, 6);
        EXPECT_GT(ev.minCoeff(), -1e-9 * ev.maxCoeff());
      } else {
        EXPECT_GT(zero, 6);  // the test detects an unstable rule
      }
    }
  }
}
