// Elasto-plastic beams through the BeamTerm (issue 9): a cantilever under an
// end moment loaded past yield and unloaded (closed form: uniform moment,
// constant curvature κ(M), end rotation κL), and a finite-difference check of
// the element tangent with plastic history in plastic loading and elastic
// unloading.
#include "solver/beams/beam_loads.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/plastic_bending.hpp"
#include "solver/beams/rotation.hpp"
#include "tests/solver/beam_test_bodies.hpp"
#include "tests/solver/beam_test_system.hpp"
#include "workflows/study/references/plastic_moment_curvature.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

using namespace stentsim::solver;
using namespace stentsim::solver::beams;
using namespace stentsim::solver::beams::testing;

namespace {

constexpr double L = 0.2;

struct Cantilever {
  PlasticBendingLaw law = PlasticBendingLaw::stent_preset();
  BeamBodyDefinition def;
  std::vector<BeamNodeDofs> dofs;
  GlobalDof ndof = 0;
  std::unique_ptr<BeamTerm> beam;
  std::unique_ptr<NodalLoadTerm> moment;
  std::unique_ptr<TestSystem> sys;
  int n = 3;
  double level = 0.0;  // end moment [N·mm]

  explicit Cantilever(int elements) : n(elements) {
    def = curve_body(straight_x(), L, n, BeamSection::circular_plastic(law));
    dofs = number_beam_dofs(def, 0, &ndof);
    dofs[0].pos = dofs[0].rot = {-1, -1, -1};
    beam = std::make_unique<BeamTerm>("cantilever", def, dofs);
    moment = std::make_unique<NodalLoadTerm>("end moment", dofs[n].rot, Eigen::Vector3d(0, 0, 1.0),
                                             [this](double) { return level; });
    sys = std::make_unique<TestSystem>(ndof);
    sys->terms = {beam.get(), moment.get()};
  }
};

// Closed-form curvature of the moment path: elastic to M_y0, then slope E_ep·I;
// unloading with slope EI from the largest (M_max, κ_max). The formula is the
// error study's (workflows/study/references/plastic_moment_curvature.hpp).
double curvature(const PlasticBendingLaw& law, double M, double M_max) {
  return stentsim::study::reference::PlasticMomentCurvature(law.E, law.E_ep, law.M_y0, law.inertia()).curvature(M, M_max);
}

}  // namespace

TEST(BeamPlasticCantilever, EndMomentLoadUnloadMatchesClosedForm) {
  Cantilever c(3);
  double M_max = 0.0, worst_rot = 0.0, worst_M = 0.0;
  const int steps = 12;
  for (int s = 1; s <= 2 * steps; ++s) {
    c.level = s <= steps ? 0.6 * s / steps : 0.6 * (2 * steps - s) / steps;
    M_max = std::max(M_max, c.level);
    c.sys->solve(static_cast<double>(s), 1e-13 * L);
    const double kappa = curvature(c.law, c.level, M_max);
    const double rot = quat_log(c.beam->rotation(c.n) * c.def.nodes[c.n].triad.conjugate()).z();
    worst_rot = std::max(worst_rot, std::abs(rot - kappa * L));
    EXPECT_NEAR(rot, kappa * L, 1e-6 * std::max(kappa * L, 1e-3)) << "step " << s;
    for (std::size_t e = 0; e < c.def.elements.size(); ++e)
      for (const SectionState& st : c.beam->section_states(c.sys->u, e)) {
        worst_M = std::max(worst_M, std::abs(st.M[2] - c.level));
        EXPECT_NEAR(st.M[2], c.level, 1e-6 * 0.6) << "step " << s;
        EXPECT_NEAR(st.M[1], 0.0, 1e-9);
      }
  }
  std::printf("cantilever 3 elements: max |end rotation − κL| = %.3e rad, max |M_gp − M| = %.3e N·mm\n", worst_rot,
              worst_M);
  // After unloading: the residual plastic curvature (κ_max − M_max/EI) keeps the end rotated.
  const double kpl = curvature(c.law, 0.6, 0.6) - 0.6 / (c.law.E * c.law.inertia());
  EXPECT_NEAR(c.beam->committed_plastic(0, 0).plastic_curvature[2], kpl, 1e-6 * kpl);
  EXPECT_NEAR(c.beam->committed_plastic(0, 0).accumulated, kpl, 1e-6 * kpl);
  // Energy: all external work is dissipated once unloaded (stored energy 0).
  EXPECT_GT(c.beam->plastic_work(), 0.0);
  EXPECT_LT(c.beam->energy(c.sys->u), 1e-9 * c.beam->plastic_work());
}

namespace {

// Scales the current deformation: u ← f·u, Λ ← exp(f'·log(Λ Λ₀ᵀ)) Λ₀ for every node.
void scale_state(Cantilever& c, double f) {
  c.sys->u *= f;
  for (std::size_t k = 0; k < c.def.nodes.size(); ++k) {
    const Eigen::Quaterniond q0 = c.def.nodes[k].triad;
    const Eigen::Vector3d th = quat_log(c.beam->rotation(static_cast<int>(k)) * q0.conjugate());
    c.beam->set_rotation(static_cast<int>(k), quat_exp(f * th) * q0);
  }
}

double element_fd_error(Cantilever& c, bool expect_yielding) {
  const DenseAssembler base = c.sys->assemble(0.0);
  // Every Gauss point on one side of the yield surface, away from it.
  for (std::size_t e = 0; e < c.def.elements.size(); ++e) {
    const auto states = c.beam->section_states(c.sys->u, e);
    for (std::size_t g = 0; g < states.size(); ++g) {
      const auto r = plastic_bending_return(c.law, states[g].Omega, c.beam->committed_plastic(e, static_cast<int>(g)));
      EXPECT_EQ(r.yielding, expect_yielding);
      EXPECT_GT(std::abs(r.phi_trial), 1e-3 * c.law.M_y0);
    }
  }
  const long n = c.sys->u.size();
  const double h = 1e-7;
  Eigen::MatrixXd Kfd(n, n);
  const Eigen::VectorXd u0 = c.sys->u;
  for (long j = 0; j < n; ++j) {
    Eigen::VectorXd du = Eigen::VectorXd::Zero(n);
    du[j] = h;
    c.sys->u = u0 + du;
    c.beam->trial(du);
    const DenseAssembler p = c.sys->assemble(0.0);
    c.sys->u = u0 - du;
    c.beam->trial(-du);
    const DenseAssembler m = c.sys->assemble(0.0);
    Kfd.col(j) = (p.R - m.R) / (2 * h);
  }
  c.sys->u = u0;
  c.beam->trial(Eigen::VectorXd::Zero(n));
  // Only the DOFs the beam has (the clamped root's numbers stay unused).
  return (Kfd - base.K).norm() / base.K.norm();
}

}  // namespace

TEST(BeamPlasticCantilever, ElementTangentMatchesFiniteDifferencesWithHistory) {
  Cantilever c(3);
  for (int s = 1; s <= 5; ++s) c.level = 0.1 * s, c.sys->solve(s, 1e-13 * L);  // committed at 0.5 N·mm, yielded
  ASSERT_GT(c.beam->committed_plastic(0, 0).accumulated, 0.0);
  Cantilever& cl = c;
  scale_state(cl, 1.15);  // further bending: plastic loading
  const double e_load = element_fd_error(cl, true);
  scale_state(cl, 0.85 / 1.15);  // less bending: elastic unloading
  const double e_unload = element_fd_error(cl, false);
  std::printf("element FD tangent rel. error: plastic loading %.3e, elastic unloading %.3e\n", e_load, e_unload);
  EXPECT_LT(e_load, 1e-6);
  EXPECT_LT(e_unload, 1e-6);
}
