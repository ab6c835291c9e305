// Elasto-plastic bending section law (paper App. C, issue 9): material-point
// closed forms along a load / unload / reverse / 90°-turn path, and a
// finite-difference check of the algorithmic tangent.
#include "common/error.hpp"
#include "solver/beams/plastic_bending.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace stentsim::solver::beams;

namespace {

struct Consts {
  PlasticBendingLaw law = PlasticBendingLaw::stent_preset();
  double I = law.inertia(), EI = law.E * I, HI = law.hardening_modulus() * I;
  double ky = law.M_y0 / EI;  // first-yield curvature
};

}  // namespace

TEST(BeamPlastic, PresetHardeningGivesElastoPlasticSlope) {
  const Consts c;
  // EI·HI/(EI+HI) = E_ep·I, the slope the appendix's H formula is built for.
  EXPECT_NEAR(c.EI * c.HI / (c.EI + c.HI), c.law.E_ep * c.I, 1e-12 * c.law.E_ep * c.I);
  EXPECT_NEAR(c.law.G * 2.0 * c.I, c.EI, 1e-14 * c.EI);  // GI_T = EI
}

TEST(BeamPlastic, LoadUnloadReverseTurnClosedForms) {
  const Consts c;
  const double tol = 1e-10;
  const double kmax = 4.0 * c.ky;
  PlasticBendingHistory h;
  // 1) Load along e2 past yield in 10 steps: M = M_y0 + E_ep·I·(κ − M_y0/EI).
  PlasticBendingResult r;
  for (int s = 1; s <= 10; ++s) {
    const double k = kmax * s / 10.0;
    r = plastic_bending_return(c.law, {0.0, k, 0.0}, h);
    h = r.history;
    const double M_exact = k <= c.ky ? c.EI * k : c.law.M_y0 + c.law.E_ep * c.I * (k - c.ky);
    const double kpl_exact = k <= c.ky ? 0.0 : k - M_exact / c.EI;
    EXPECT_NEAR(r.M[1], M_exact, tol * c.law.M_y0) << "step " << s;
    EXPECT_NEAR(r.M[2], 0.0, tol * c.law.M_y0);
    EXPECT_NEAR(h.plastic_curvature[1], kpl_exact, tol * c.ky);
    EXPECT_NEAR(h.accumulated, kpl_exact, tol * c.ky);
    EXPECT_EQ(r.yielding, k > c.ky);
  }
  const double M1 = c.law.M_y0 + c.law.E_ep * c.I * (kmax - c.ky);
  const double kpl1 = kmax - M1 / c.EI, acc1 = kpl1;
  // 2) Unload to zero moment (κ = κ_pl): slope EI, history unchanged. (Going
  // on to κ = 0 would yield in reverse already: the elastic range 2·M_y is
  // smaller than EI·κ_max here.)
  for (int s = 1; s <= 5; ++s) {
    const double k = kmax - (kmax - kpl1) * s / 5.0;
    r = plastic_bending_return(c.law, {0.0, k, 0.0}, h);
    EXPECT_FALSE(r.yielding);
    EXPECT_NEAR(r.M[1], M1 - c.EI * (kmax - k), tol * c.law.M_y0);
    h = r.history;
  }
  EXPECT_NEAR(h.plastic_curvature[1], kpl1, tol * c.ky);
  EXPECT_NEAR(r.M[1], 0.0, tol * c.law.M_y0);
  // 3) Reverse: elastic down to κ_r where M = −(M_y0 + H·I·Ω̄), then plastic
  // with M = −(M_y0 + H·I·(Ω̄₁ + κ_pl1 − κ_pl)) = EI(κ − κ_pl).
  const double My1 = c.law.M_y0 + c.HI * acc1;
  const double k_rev = kpl1 - My1 / c.EI;
  r = plastic_bending_return(c.law, {0.0, k_rev + 1e-6 * c.ky, 0.0}, h);
  EXPECT_FALSE(r.yielding);
  r = plastic_bending_return(c.law, {0.0, k_rev - 1e-6 * c.ky, 0.0}, h);
  EXPECT_TRUE(r.yielding);
  for (int s = 1; s <= 8; ++s) {
    const double k = kpl1 + (-kmax - kpl1) * s / 8.0;
    r = plastic_bending_return(c.law, {0.0, k, 0.0}, h);
    h = r.history;
    if (k > k_rev) {
      EXPECT_FALSE(r.yielding) << "step " << s;
      EXPECT_NEAR(r.M[1], c.EI * (k - kpl1), tol * c.law.M_y0);
    } else {
      const double kpl = (c.EI * k + c.law.M_y0 + c.HI * acc1 + c.HI * kpl1) / (c.EI + c.HI);
      EXPECT_NEAR(h.plastic_curvature[1], kpl, tol * c.ky) << "step " << s;
      EXPECT_NEAR(h.accumulated, acc1 + kpl1 - kpl, tol * c.ky);
      EXPECT_NEAR(r.M[1], c.EI * (k - kpl), tol * c.law.M_y0);
      EXPECT_NEAR(r.M[1], -(c.law.M_y0 + c.HI * h.accumulated), tol * c.law.M_y0);
    }
  }
  // 4) Turn the bending direction by 90°: Ω = κ_max e3 in one step. The trial
  // elastic curvature is κ_max e3 − κ_pl e2; the return is radial along it.
  const Eigen::Vector3d kpl2 = h.plastic_curvature;
  const double acc2 = h.accumulated;
  const Eigen::Vector2d el_tr(-kpl2[1], kmax);
  const double phi = c.EI * el_tr.norm() - (c.law.M_y0 + c.HI * acc2);
  ASSERT_GT(phi, 0.0);
  const double dg = phi / (c.EI + c.HI);
  const Eigen::Vector2d n = el_tr.normalized();
  r = plastic_bending_return(c.law, {0.0, 0.0, kmax}, h);
  EXPECT_TRUE(r.yielding);
  EXPECT_NEAR(r.history.accumulated, acc2 + dg, tol * c.ky);
  EXPECT_NEAR(r.history.plastic_curvature[1], kpl2[1] + dg * n[0], tol * c.ky);
  EXPECT_NEAR(r.history.plastic_curvature[2], dg * n[1], tol * c.ky);
  EXPECT_NEAR(r.M.tail<2>().norm(), c.law.M_y0 + c.HI * (acc2 + dg), tol * c.law.M_y0);  // on the yield surface
  const Eigen::Vector2d el = Eigen::Vector2d(0.0, kmax) - r.history.plastic_curvature.tail<2>();
  EXPECT_NEAR((r.M.tail<2>() - c.EI * el).norm(), 0.0, tol * c.law.M_y0);  // M_b = EI Ω_b^el
}

TEST(BeamPlastic, TorsionStaysElasticAndSplitsOnBeamAxis) {
  const Consts c;
  PlasticBendingHistory h;
  // A large torsional curvature never yields; bending below yield stays elastic.
  const auto r = plastic_bending_return(c.law, {50.0 * c.ky, 0.5 * c.ky, 0.0}, h);
  EXPECT_FALSE(r.yielding);
  EXPECT_NEAR(r.M[0], c.EI * 50.0 * c.ky, 1e-12 * c.law.M_y0);
  EXPECT_NEAR(r.M[1], 0.5 * c.law.M_y0, 1e-12 * c.law.M_y0);
  // Torsion added to a yielding bending state leaves the return unchanged.
  const auto a = plastic_bending_return(c.law, {0.0, 3.0 * c.ky, 1.0 * c.ky}, h);
  const auto b = plastic_bending_return(c.law, {7.0 * c.ky, 3.0 * c.ky, 1.0 * c.ky}, h);
  EXPECT_TRUE(a.yielding);
  EXPECT_NEAR((a.M.tail<2>() - b.M.tail<2>()).norm(), 0.0, 1e-14);
  EXPECT_NEAR(a.history.accumulated, b.history.accumulated, 1e-16);
  EXPECT_EQ(b.history.plastic_curvature[0], 0.0);
}

namespace {

// Central differences of M(Ω) with the committed history fixed, vs the tangent.
double tangent_fd_error(const PlasticBendingLaw& law, const Eigen::Vector3d& Omega, const PlasticBendingHistory& h,
                        double hstep) {
  const auto r = plastic_bending_return(law, Omega, h);
  Eigen::Matrix3d fd;
  for (int j = 0; j < 3; ++j) {
    Eigen::Vector3d p = Omega, m = Omega;
    p[j] += hstep;
    m[j] -= hstep;
    const auto rp = plastic_bending_return(law, p, h), rm = plastic_bending_return(law, m, h);
    EXPECT_EQ(rp.yielding, r.yielding);  // no FD step crosses the yield surface
    EXPECT_EQ(rm.yielding, r.yielding);
    fd.col(j) = (rp.M - rm.M) / (2.0 * hstep);
  }
  return (fd - r.C).norm() / r.C.norm();
}

}  // namespace

TEST(BeamPlastic, AlgorithmicTangentMatchesFiniteDifferences) {
  const Consts c;
  const double hstep = 1e-6 * c.ky;
  // Committed history from an oblique load past yield.
  PlasticBendingHistory h = plastic_bending_return(c.law, {0.2 * c.ky, 2.0 * c.ky, -1.5 * c.ky}, {}).history;
  ASSERT_GT(h.accumulated, 0.0);
  // Plastic loading in a new direction (non-proportional: the n⊗n and
  // (1 − n⊗n) parts both matter).
  const Eigen::Vector3d plastic_state(0.3 * c.ky, 1.0 * c.ky, 3.5 * c.ky);
  const auto rp = plastic_bending_return(c.law, plastic_state, h);
  ASSERT_TRUE(rp.yielding);
  ASSERT_GT(std::abs(rp.phi_trial), 1e-3 * c.law.M_y0);
  EXPECT_LT(tangent_fd_error(c.law, plastic_state, h, hstep), 1e-7);
  // Elastic unloading from the committed plastic state.
  const Eigen::Vector3d unload_state = h.plastic_curvature + Eigen::Vector3d(0.1 * c.ky, 0.4 * c.ky, -0.3 * c.ky);
  const auto ru = plastic_bending_return(c.law, unload_state, h);
  ASSERT_FALSE(ru.yielding);
  ASSERT_GT(std::abs(ru.phi_trial), 1e-3 * c.law.M_y0);
  EXPECT_LT(tangent_fd_error(c.law, unload_state, h, hstep), 1e-7);
}

TEST(BeamPlastic, BadParametersAreInputErrors) {
  PlasticBendingLaw law = PlasticBendingLaw::stent_preset();
  EXPECT_NO_THROW(law.validate("test"));
  law.E_ep = law.E;
  EXPECT_THROW(law.validate("test"), stentsim::InputError);
  law = PlasticBendingLaw::stent_preset();
  law.M_y0 = 0.0;
  EXPECT_THROW(law.validate("test"), stentsim::InputError);
}
