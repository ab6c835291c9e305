// Material summands: tangent vs finite differences of the stress, stress vs
// finite differences of the energy, HGO uniaxial/equibiaxial closed forms,
// viscous update and guards.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <cstdio>
#include <random>

#include "solver/materials/presets.hpp"
#include "tests/solver/fd_check.hpp"

namespace stentsim::solver {
namespace {

Mat3 random_f(std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Mat3 f = Mat3::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f(i, j) += u(rng);
  return f;
}

// svMultiPhysics's HGO (the peer tube's media): decoupled neo-Hooke, two families on Ibar4
// (one acting both ways, one tension-only, at different directions).
Material decoupled_hgo() {
  Material m;
  m.name = "decoupled HGO";
  m.decoupled_matrix = DecoupledNeoHooke::from_young_poisson(0.1566, 0.45);
  FiberFamilySpec f;
  f.law = {0.64e-3, 3.54, false, 1.0, true};
  FiberFamilySpec g;
  g.law = {5.1e-3, 15.4, true, 1.0, true};
  m.fibers = {f, g};
  return m;
}

std::vector<Material> all_materials() {
  std::vector<Material> ms;
  Material nh;
  nh.name = "neo-hooke nu=0.45";
  nh.matrix = CoupledNeoHooke::from_young_poisson(1.0, 0.45);
  ms.push_back(nh);
  nh.name = "neo-hooke nu=0";
  nh.matrix = CoupledNeoHooke::from_young_poisson(17.0, 0.0);
  ms.push_back(nh);
  Material fib;
  fib.name = "fiber tension-only";
  FiberFamilySpec f;
  f.law = {2.0, 1.5, true, 1.0};
  fib.fibers = {f, f};
  ms.push_back(fib);
  for (const auto& p : material_preset_names()) ms.push_back(material_preset(p));
  ms.push_back(decoupled_hgo());
  Material dnh;
  dnh.name = "decoupled neo-hooke nu=0";
  dnh.decoupled_matrix = DecoupledNeoHooke::from_young_poisson(3.0, 0.0);
  ms.push_back(dnh);
  return ms;
}

std::array<Vec3, kMaxFiberFamilies> random_dirs(std::mt19937& rng) {
  std::normal_distribution<double> n;
  std::array<Vec3, kMaxFiberFamilies> d;
  for (auto& v : d) v = Vec3(n(rng), n(rng), n(rng)).normalized();
  return d;
}

// S(C) with C = C0 + 2 dE (engineering shear in Voigt dE).
Vec6 stress_at(const Material& m, const Mat3& c0, const Vec6& de, const Vec3* dirs) {
  Mat3 e;
  e << de(0), de(3) / 2, de(5) / 2, de(3) / 2, de(1), de(4) / 2, de(5) / 2, de(4) / 2, de(2);
  Vec6 s;
  EXPECT_TRUE(m.elastic(c0 + 2 * e, dirs, s, nullptr).ok);
  return s;
}

TEST(SolverMaterials, TangentMatchesFiniteDifferences) {
  std::mt19937 rng(7);
  double worst = 0.0;
  for (const auto& m : all_materials()) {
    for (int trial = 0; trial < 5; ++trial) {
      const Mat3 f = random_f(rng, 0.25);
      const Mat3 c = f.transpose() * f;
      const auto dirs = random_dirs(rng);
      Vec6 s;
      Mat6 d;
      ASSERT_TRUE(m.elastic(c, dirs.data(), s, &d).ok) << m.name;
      const Eigen::MatrixXd dfd = test::fd_jacobian(
          [&](const Eigen::VectorXd& x) -> Eigen::VectorXd { return stress_at(m, c, x, dirs.data()); },
          Eigen::VectorXd::Zero(6), 1e-6);
      if (dfd.norm() < 1e-14) {  // e.g. a tension-only fiber in compression
        EXPECT_EQ(d.norm(), 0.0) << m.name;
        continue;
      }
      const double err = test::rel_error(d, dfd);
      worst = std::max(worst, err);
      EXPECT_LT(err, 1e-6) << m.name << " trial " << trial;
      EXPECT_LT((d - d.transpose()).norm(), 1e-12 * d.norm()) << m.name << ": tangent not symmetric";
    }
  }
  std::printf("worst relative FD error of material tangents: %.2e\n", worst);
}

TEST(SolverMaterials, StressIsEnergyDerivative) {
  std::mt19937 rng(11);
  for (const auto& m : all_materials()) {
    const Mat3 f = random_f(rng, 0.25);
    const Mat3 c = f.transpose() * f;
    const auto dirs = random_dirs(rng);
    Vec6 s;
    ASSERT_TRUE(m.elastic(c, dirs.data(), s, nullptr).ok);
    // dPsi/dE_v = S_v with engineering shears.
    const Eigen::MatrixXd dw = test::fd_jacobian(
        [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
          Mat3 e;
          e << x(0), x(3) / 2, x(5) / 2, x(3) / 2, x(1), x(4) / 2, x(5) / 2, x(4) / 2, x(2);
          return Eigen::VectorXd::Constant(1, m.energy(c + 2 * e, dirs.data()));
        },
        Eigen::VectorXd::Zero(6), 1e-6);
    EXPECT_LT(test::rel_error(dw.transpose(), s), 1e-7) << m.name;
  }
}

TEST(SolverMaterials, StressFreeReference) {
  for (const auto& m : all_materials()) {
    Vec6 s;
    Mat6 d;
    std::array<Vec3, kMaxFiberFamilies> dirs;
    dirs.fill(Vec3::UnitX());
    ASSERT_TRUE(m.elastic(Mat3::Identity(), dirs.data(), s, &d).ok);
    EXPECT_LT(s.norm(), 1e-14) << m.name;
  }
}

// Both matrices at C = I are Hooke's law with the same lambda and mu: the coupled one by
// lambda = 4 c beta, the decoupled one by lambda = K - 2 mu / 3.
TEST(SolverMaterials, SmallStrainLimitIsHooke) {
  for (bool decoupled : {false, true}) {
    for (double nu : {0.0, 0.3, 0.45}) {
      const double young = 2.5;
      Material m;
      if (decoupled) m.decoupled_matrix = DecoupledNeoHooke::from_young_poisson(young, nu);
      else m.matrix = CoupledNeoHooke::from_young_poisson(young, nu);
      Vec6 s;
      Mat6 d;
      ASSERT_TRUE(m.elastic(Mat3::Identity(), nullptr, s, &d).ok);
      EXPECT_LT(s.norm(), 1e-15);
      const double lambda = young * nu / ((1 + nu) * (1 - 2 * nu)), mu = young / (2 * (1 + nu));
      EXPECT_NEAR(d(0, 0), lambda + 2 * mu, 1e-12) << "decoupled " << decoupled << " nu " << nu;
      EXPECT_NEAR(d(0, 1), lambda, 1e-12) << "decoupled " << decoupled << " nu " << nu;
      EXPECT_NEAR(d(3, 3), mu, 1e-12) << "decoupled " << decoupled << " nu " << nu;
    }
  }
}

// Decoupled HGO under a pure dilatation C = J^(2/3) 1: Ibar1 = 3 and Ibar4 = 1, so neither the
// isochoric matrix nor the fibers (on Ibar4) stress it; S = K/2 (J^2 - 1) C^-1 alone. A fiber on
// I4 would add 2 k1 (I4 - 1) exp(..) M (x) M.
TEST(SolverMaterials, DecoupledHgoDilatationIsVolumetricOnly) {
  const Material m = decoupled_hgo();
  std::array<Vec3, kMaxFiberFamilies> dirs;
  dirs.fill(Vec3(1, 2, 2) / 3.0);
  for (double j : {0.9, 1.1, 1.4}) {
    const Mat3 c = std::pow(j, 2.0 / 3.0) * Mat3::Identity();
    Vec6 s;
    ASSERT_TRUE(m.elastic(c, dirs.data(), s, nullptr).ok);
    const double k = m.decoupled_matrix->kappa;
    const Vec6 expected = to_voigt_stress(0.5 * k * (j * j - 1) * c.inverse());
    EXPECT_LT((s - expected).norm(), 1e-14 * expected.norm()) << "J = " << j;
  }
  // Isochoric uniaxial stretch along the first fiber, F = diag(l, l^-1/2, l^-1/2): Ibar4 = I4 = l^2,
  // sigma_11 - sigma_22 = mu (l^2 - 1/l) + 2 k1 (l^2 - 1) exp(k2 (l^2 - 1)^2) l^2.
  dirs[0] = Vec3::UnitX();
  dirs[1] = Vec3::UnitY();  // tension-only family in compression (I4 = 1/l < 1): nothing
  for (double l : {1.05, 1.2}) {
    const Mat3 f = Vec3(l, 1 / std::sqrt(l), 1 / std::sqrt(l)).asDiagonal();
    Vec6 s;
    ASSERT_TRUE(m.elastic(f.transpose() * f, dirs.data(), s, nullptr).ok);
    const Mat3 sigma = cauchy_from_pk2(f, from_voigt_stress(s));
    const double e = l * l - 1, k1 = m.fibers[0].law.k1, k2 = m.fibers[0].law.k2;
    const double expected = m.decoupled_matrix->mu * (l * l - 1 / l) + 2 * k1 * e * std::exp(k2 * e * e) * l * l;
    EXPECT_NEAR(sigma(0, 0) - sigma(1, 1), expected, 1e-13);
    EXPECT_NEAR(sigma.trace(), 0.0, 1e-13);  // J = 1: no volumetric stress, and the isochoric parts are deviatoric
  }
}

// HGO fiber family along e1 alone (no matrix): uniaxial stretch lambda along the fiber,
// S11 = 2 Psi'(I4) = 2 k1 (l^2 - 1) exp(k2 (l^2 - 1)^2), sigma11 = l^2 S11.
TEST(SolverMaterials, FiberUniaxialClosedForm) {
  Material m;
  FiberFamilySpec f;
  f.law = {0.64e-3, 3.54, false, 1.0};
  m.fibers = {f};
  const Vec3 dir = Vec3::UnitX();
  for (double l : {0.9, 1.0, 1.1, 1.3}) {
    Mat3 c = Mat3::Identity();
    c(0, 0) = l * l;
    c(1, 1) = c(2, 2) = 1.0 / l;  // lateral contraction does not matter to the fiber
    Vec6 s;
    ASSERT_TRUE(m.elastic(c, &dir, s, nullptr).ok);
    const double e = l * l - 1;
    EXPECT_NEAR(s(0), 2 * f.law.k1 * e * std::exp(f.law.k2 * e * e), 1e-15);
    EXPECT_NEAR(s(1), 0.0, 1e-15);
  }
  // tension_only: nothing in compression.
  m.fibers[0].law.tension_only = true;
  Mat3 c = Mat3::Identity();
  c(0, 0) = 0.8;
  Vec6 s;
  ASSERT_TRUE(m.elastic(c, &dir, s, nullptr).ok);
  EXPECT_EQ(s.norm(), 0.0);
}

// Equibiaxial stretch of the adventitia preset in the (circ, long) plane with
// fibers at +-40 deg, matrix + fibers: Cauchy stress closed form
// sigma_cc = 2c (l^2 - J^-2beta)/J + (2/J) sum_f 2 Psi'_f l^2 cos^2 phi, J = l^2 l3.
TEST(SolverMaterials, AdventitiaEquibiaxialClosedForm) {
  const Material m = material_preset("adventitia");
  const double phi = 40.0 * std::numbers::pi / 180.0;
  // frame: e1 radial, e2 circumferential, e3 longitudinal
  std::array<Vec3, kMaxFiberFamilies> dirs;
  dirs[0] = Vec3(0, std::cos(phi), std::sin(phi));
  dirs[1] = Vec3(0, std::cos(phi), -std::sin(phi));
  const auto& nh = *m.matrix;
  for (double l : {1.05, 1.1, 1.2}) {
    const double l3 = 0.93;  // any radial stretch: closed form holds for the full 3D state
    const Mat3 f = Vec3(l3, l, l).asDiagonal();
    Vec6 s;
    ASSERT_TRUE(m.elastic(f.transpose() * f, dirs.data(), s, nullptr).ok);
    const Mat3 sigma = cauchy_from_pk2(f, from_voigt_stress(s));
    const double j = l * l * l3, jp = std::pow(j, -2 * nh.beta);
    const double i4 = l * l;  // cos^2 + sin^2 times l^2
    const double e = i4 - 1, k1 = m.fibers[0].law.k1, k2 = m.fibers[0].law.k2;
    const double psi1 = k1 * e * std::exp(k2 * e * e);
    const double scc = 2 * nh.c * (l * l - jp) / j + 2.0 * 2 * psi1 * l * l * std::cos(phi) * std::cos(phi) / j;
    const double sll = 2 * nh.c * (l * l - jp) / j + 2.0 * 2 * psi1 * l * l * std::sin(phi) * std::sin(phi) / j;
    const double srr = 2 * nh.c * (l3 * l3 - jp) / j;
    EXPECT_NEAR(sigma(1, 1), scc, 1e-12 * std::abs(scc));
    EXPECT_NEAR(sigma(2, 2), sll, 1e-12 * std::abs(sll));
    EXPECT_NEAR(sigma(0, 0), srr, 1e-12 * std::abs(srr) + 1e-15);
    EXPECT_NEAR(sigma(1, 2), 0.0, 1e-14);  // +-phi shear cancels
  }
}

TEST(SolverMaterials, NeoHookeGuardReportsInsteadOfInf) {
  Material m;
  m.matrix = CoupledNeoHooke::from_young_poisson(1.0, 0.4999);  // beta ~ 2500
  Vec6 s;
  Mat6 d;
  EXPECT_FALSE(m.elastic(Mat3::Identity() * 0.5, nullptr, s, &d).ok);  // J = 0.35: J^-5000 overflows
  EXPECT_FALSE(m.elastic(-Mat3::Identity(), nullptr, s, &d).ok);
  EXPECT_TRUE(m.elastic(Mat3::Identity() * 0.9999, nullptr, s, &d).ok);
}

TEST(SolverMaterials, ViscousUpdateIsExactForLinearStress) {
  // S_inf(t) = a t, Q(0) = 0: dQ/dt + Q/tau = beta a  ->  Q = beta a tau (1 - exp(-t/tau)).
  const ViscousBranch v{0.5, 0.3};
  const double a = 2.0;
  ViscousHistory h;
  double t = 0.0;
  for (double dt : {0.1, 0.05, 0.3, 0.02, 0.53}) {
    Vec6 s_new = Vec6::Constant(a * (t + dt));
    h.q = v.update(h, s_new, dt);
    h.s_inf = s_new;
    t += dt;
    EXPECT_NEAR(h.q(0), v.beta * a * v.tau * (1 - std::exp(-t / v.tau)), 1e-14);
  }
  // Relaxation at constant S_inf.
  const Vec6 q0 = h.q;
  h.q = v.update(h, h.s_inf, 0.5);
  EXPECT_NEAR(h.q(0), q0(0) * std::exp(-1.0), 1e-14);
}

}  // namespace
}  // namespace stentsim::solver
