// Objectivity and path independence of the Crisfield–Jelenić interpolation (issue 8).
#include "solver/beams/beam_loads.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/rotation.hpp"
#include "tests/solver/beam_test_bodies.hpp"
#include "tests/solver/beam_test_system.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace stentsim::solver;
using namespace stentsim::solver::beams;
using namespace stentsim::solver::beams::testing;

namespace {

BeamSection section() { return BeamSection::from_values(1e3, 4e2, 1.0, 0.8, 0.7, 0.1, 0.15, 0.2); }

void random_state(BeamTerm& beam, Eigen::VectorXd& u, unsigned seed) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (long i = 0; i < u.size(); ++i) u[i] = 0.4 * uni(g);
  const Eigen::Quaterniond big = quat_exp(Eigen::Vector3d(1.5, -0.7, 1.9));
  for (std::size_t n = 0; n < beam.body().nodes.size(); ++n)
    beam.set_rotation(static_cast<int>(n),
                      quat_exp(0.8 * Eigen::Vector3d(uni(g), uni(g), uni(g))) * big * beam.body().nodes[n].triad);
}

double rel(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double scale) { return (a - b).norm() / scale; }

void check_objectivity(BeamInterpolation kind) {
  BeamBodyDefinition def = curve_body(helix(2.0, 1.0), 6.0, 3, section(), kind);
  GlobalDof n = 0;
  const auto dofs = number_beam_dofs(def, 0, &n);
  BeamTerm beam("b", def, dofs);
  TestSystem sys(n);
  sys.terms = {&beam};
  random_state(beam, sys.u, 3);
  std::vector<std::vector<SectionState>> before;
  for (std::size_t e = 0; e < def.elements.size(); ++e) before.push_back(beam.section_states(sys.u, e));
  const double E0 = beam.energy(sys.u);
  const DenseAssembler a0 = sys.assemble(0.0);

  // Superpose a rigid rotation Q (and a translation c) on the deformed state.
  const Eigen::Quaterniond Q = quat_exp(Eigen::Vector3d(-2.1, 0.9, 1.4));
  const Eigen::Vector3d c(3.0, -1.0, 2.0);
  const Eigen::Matrix3d Qm = Q.toRotationMatrix();
  Eigen::VectorXd u = sys.u;
  for (std::size_t k = 0; k < def.nodes.size(); ++k) {
    const int node = static_cast<int>(k);
    if (dofs[k].pos[0] >= 0) {
      const Eigen::Vector3d r = Qm * beam.position(sys.u, node) + c;
      const Eigen::Vector3d t = Qm * beam.tangent(sys.u, node);
      const Eigen::Vector3d X = def.nodes[k].position, T0 = def.nodes[k].triad.toRotationMatrix().col(0);
      for (int i = 0; i < 3; ++i) {
        u[dofs[k].pos[i]] = r[i] - X[i];
        if (dofs[k].tan[i] >= 0) u[dofs[k].tan[i]] = t[i] - T0[i];
      }
    }
    beam.set_rotation(node, Q * beam.rotation(node));
  }
  sys.u = u;
  const double E1 = beam.energy(sys.u);
  EXPECT_LT(std::abs(E1 - E0) / E0, 1e-10);
  double worst = 0.0;
  for (std::size_t e = 0; e < def.elements.size(); ++e) {
    const auto after = beam.section_states(sys.u, e);
    for (std::size_t p = 0; p < after.size(); ++p) {
      const SectionState &s0 = before[e][p], &s1 = after[p];
      worst = std::max({worst, rel(s1.Gamma, s0.Gamma, s0.Gamma.norm()), rel(s1.Omega, s0.Omega, s0.Omega.norm()),
                        rel(s1.F, s0.F, s0.F.norm()), rel(s1.M, s0.M, s0.M.norm())});
      // the triad itself is rotated: Λ → QΛ
      EXPECT_LT((s1.triad - Qm * s0.triad).norm(), 1e-12);
    }
  }
  std::printf("objectivity: energy change %.2e, worst relative change of Γ, Ω, F, M %.2e\n",
              std::abs(E1 - E0) / E0, worst);
  EXPECT_LT(worst, 1e-10);
  // Spatial residual blocks rotate with Q (forces and moments are vectors).
  const DenseAssembler a1 = sys.assemble(0.0);
  double res = 0.0;
  for (long i = 0; i < n; i += 3) res = std::max(res, (a1.R.segment<3>(i) - Qm * a0.R.segment<3>(i)).norm());
  EXPECT_LT(res / a0.R.norm(), 1e-10);
}

}  // namespace

TEST(BeamObjectivity, HermiteRigidRotationLeavesStrainsResultantsEnergy) { check_objectivity(BeamInterpolation::hermite3); }
TEST(BeamObjectivity, LagrangeRigidRotationLeavesStrainsResultantsEnergy) {
  check_objectivity(BeamInterpolation::lagrange2);
}

TEST(BeamObjectivity, NonObjectiveInterpolationWouldBeDetected) {
  // Sanity of the test itself: rotating only some nodal triads (not a rigid
  // motion) does change the strains.
  BeamBodyDefinition def = curve_body(helix(2.0, 1.0), 2.0, 1, section());
  GlobalDof n = 0;
  BeamTerm beam("b", def, number_beam_dofs(def, 0, &n));
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  const auto s0 = beam.section_states(u, 0);
  beam.set_rotation(1, quat_exp(Eigen::Vector3d(0, 0, 0.3)) * beam.rotation(1));
  const auto s1 = beam.section_states(u, 0);
  EXPECT_GT((s1[0].Omega - s0[0].Omega).norm(), 1e-3);
}

namespace {

// Piecewise-linear load path 0 → A → B → 0 over t ∈ [0, 3].
Eigen::Vector3d along(double t, const Eigen::Vector3d& A, const Eigen::Vector3d& B) {
  if (t <= 1) return t * A;
  if (t <= 2) return (2 - t) * A + (t - 1) * B;
  return (3 - t) * B;
}

}  // namespace

TEST(BeamPathIndependence, ClosedLoadPathReturnsToStart) {
  for (BeamInterpolation kind : {BeamInterpolation::hermite3, BeamInterpolation::lagrange2}) {
    const double Lb = 10.0;
    const BeamSection sec = BeamSection::from_values(1e4, 5e3, 1.0, 1.0, 1.0, 1.0 / 12, 1.0 / 10, 1.0 / 6);
    BeamBodyDefinition def = curve_body(straight_x(), Lb, 6, sec, kind);
    GlobalDof n = 0;
    auto dofs = number_beam_dofs(def, 0, &n);
    dofs[0].pos = dofs[0].rot = dofs[0].tan = {-1, -1, -1};
    BeamTerm beam("b", def, dofs);
    const double EI = 1e4 / 12;
    const Eigen::Vector3d MA(0.2 * EI / Lb, 2.0 * EI / Lb, 0.5 * EI / Lb), MB(-0.4 * EI / Lb, 0.3 * EI / Lb, 1.8 * EI / Lb);
    const Eigen::Vector3d FA(0, 0.05 * EI / (Lb * Lb), 0.1 * EI / (Lb * Lb)), FB(0.2 * EI / (Lb * Lb), 0, 0.1 * EI / (Lb * Lb));
    NodalLoadTerm moment("m", dofs[6].rot, Eigen::Vector3d(1, 0, 0), nullptr);
    NodalLoadTerm force("f", dofs[6].pos, Eigen::Vector3d(1, 0, 0), nullptr);
    TestSystem sys(n);
    sys.terms = {&beam, &moment, &force};
    auto at_time = [&](double t) {
      moment.set_value(along(t, MA, MB));
      force.set_value(along(t, FA, FB));
      sys.solve(t, 1e-12 * Lb);
    };
    double max_tip_angle = 0.0;
    Eigen::VectorXd uA;
    std::vector<Eigen::Quaterniond> qA;
    for (int step = 1; step <= 30; ++step) {
      const double t = step / 10.0;
      at_time(t);
      max_tip_angle = std::max(max_tip_angle, quat_log(beam.rotation(6) * def.nodes[6].triad.conjugate()).norm());
      if (step == 10) {
        uA = sys.u;
        for (std::size_t k = 0; k < def.nodes.size(); ++k) qA.push_back(beam.rotation(static_cast<int>(k)));
      }
    }
    EXPECT_GT(max_tip_angle, std::numbers::pi / 2);  // the path really turns the tip beyond 90°
    double du = 0.0, dq = 0.0;
    for (std::size_t k = 0; k < def.nodes.size(); ++k) {
      if (dofs[k].pos[0] >= 0) du = std::max(du, (beam.position(sys.u, static_cast<int>(k)) - def.nodes[k].position).norm());
      if (dofs[k].tan[0] >= 0)
        du = std::max(du, (beam.tangent(sys.u, static_cast<int>(k)) - def.nodes[k].triad.toRotationMatrix().col(0)).norm());
      dq = std::max(dq, quat_log(beam.rotation(static_cast<int>(k)) * def.nodes[k].triad.conjugate()).norm());
    }
    std::printf("%s: max tip rotation on the path %.3f rad; back at zero load: |Δr| %.2e, |Δθ| %.2e\n",
                kind == BeamInterpolation::hermite3 ? "hermite" : "lagrange", max_tip_angle, du, dq);
    EXPECT_LT(du, 1e-10 * Lb);
    EXPECT_LT(dq, 1e-10);

    // Reaching load A again by another route (0 → B → A) gives the same state.
    for (int step = 1; step <= 10; ++step) {
      const double s = step / 10.0;
      moment.set_value(s * MB);
      force.set_value(s * FB);
      sys.solve(s, 1e-12 * Lb);
    }
    for (int step = 1; step <= 10; ++step) {
      const double s = step / 10.0;
      moment.set_value((1 - s) * MB + s * MA);
      force.set_value((1 - s) * FB + s * FA);
      sys.solve(s, 1e-12 * Lb);
    }
    double dA = 0.0;
    for (std::size_t k = 0; k < def.nodes.size(); ++k)
      dA = std::max(dA, quat_log(beam.rotation(static_cast<int>(k)) * qA[k].conjugate()).norm());
    for (long i = 0; i < n; ++i) {
      bool rot = false;
      for (const auto& d : dofs)
        for (auto r : d.rot) rot = rot || r == i;
      if (!rot) dA = std::max(dA, std::abs(sys.u[i] - uA[i]) / Lb);
    }
    EXPECT_LT(dA, 1e-10);
  }
}
