// Pins the named material presets to the paper's parameters (Section 2.1:
// media/adventitia E, nu, k1, k2, phi; Section 2.3: balloon; App. B: tau,
// beta) and DESIGN.md §5/§8 (intima as media, balloon dissipation tau 0.5 s,
// beta 0.05, fibers both ways by default), and the load curve: piecewise
// linear between its points, constant beyond its ends, bad points rejected.
#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "solver/materials/presets.hpp"
#include "solver/terms/load_curve.hpp"

namespace stentsim::solver {
namespace {

struct Layer {
  double young, poisson;                  // MPa, -
  std::vector<std::array<double, 3>> fibers;  // k1 (MPa), k2, angle (deg from circumferential)
  bool viscous;
  double tau = 0, beta = 0;
};

// E and nu back from the stored (c, beta): c = E / (4 (1 + nu)), beta = nu / (1 - 2 nu).
void expect_matrix(const Material& m, double young, double poisson) {
  ASSERT_TRUE(m.matrix) << m.name;
  const double nu = m.matrix->beta / (1.0 + 2.0 * m.matrix->beta);
  const double e = 4.0 * m.matrix->c * (1.0 + nu);
  EXPECT_NEAR(e, young, 1e-12 * young) << m.name;
  EXPECT_NEAR(nu, poisson, 1e-12) << m.name;
}

void expect_layer(const std::string& name, const Layer& want) {
  const Material m = material_preset(name);
  EXPECT_EQ(m.name, name);
  expect_matrix(m, want.young, want.poisson);
  ASSERT_EQ(m.fibers.size(), want.fibers.size()) << name;
  for (std::size_t f = 0; f < want.fibers.size(); ++f) {
    EXPECT_DOUBLE_EQ(m.fibers[f].law.k1, want.fibers[f][0]) << name << " family " << f;
    EXPECT_DOUBLE_EQ(m.fibers[f].law.k2, want.fibers[f][1]) << name << " family " << f;
    EXPECT_DOUBLE_EQ(m.fibers[f].angle_deg, want.fibers[f][2]) << name << " family " << f;
    EXPECT_FALSE(m.fibers[f].global_direction) << name << ": fiber angles refer to the element frame";
    EXPECT_FALSE(m.fibers[f].law.tension_only) << name << ": the paper's form acts both ways (DESIGN.md §8)";
    EXPECT_DOUBLE_EQ(m.fibers[f].law.multiplicity, 1.0) << name;
  }
  EXPECT_EQ(m.viscous.has_value(), want.viscous) << name;
  if (want.viscous && m.viscous) {
    EXPECT_DOUBLE_EQ(m.viscous->tau, want.tau) << name;
    EXPECT_DOUBLE_EQ(m.viscous->beta, want.beta) << name;
  }
}

TEST(SolverPresets, ArteryLayersAreThePapers) {
  // Paper 2.1: media E 156.6 kPa, adventitia 15.66 kPa, nu 0.45; k1 0.64 kPa / 3.54 (media),
  // 5.1 kPa / 15.4 (adventitia); phi_M = 0 deg, phi_A = +-40 deg; App. B: tau 0.5 s, beta 0.3.
  expect_layer("media", {0.1566, 0.45, {{0.64e-3, 3.54, 0.0}, {0.64e-3, 3.54, -0.0}}, true, 0.5, 0.3});
  expect_layer("intima", {0.1566, 0.45, {{0.64e-3, 3.54, 0.0}, {0.64e-3, 3.54, -0.0}}, true, 0.5, 0.3});
  expect_layer("adventitia", {0.01566, 0.45, {{5.1e-3, 15.4, 40.0}, {5.1e-3, 15.4, -40.0}}, false});
}

TEST(SolverPresets, BalloonIsThePapers) {
  // Paper 2.3: E 17 MPa, nu 0; longitudinal k1 1000, k2 0.01; circumferential k1 1.5e-7, k2 0.35.
  // Dissipation not given: tau 0.5 s, beta 0.05 (DESIGN.md §8).
  expect_layer("balloon", {17.0, 0.0, {{1000.0, 0.01, 90.0}, {1.5e-7, 0.35, 0.0}}, true, 0.5, 0.05});
}

TEST(SolverPresets, NamesAndUnknownPreset) {
  auto names = material_preset_names();
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"adventitia", "balloon", "intima", "media"}));
  EXPECT_THROW(material_preset("Media"), std::out_of_range);
}

TEST(SolverLoadCurve, PiecewiseLinearAndConstantOutside) {
  const LoadCurve c({{0.0, 0.0}, {1.0, 2.0}, {3.0, -1.0}});
  EXPECT_DOUBLE_EQ(c(0.0), 0.0);
  EXPECT_DOUBLE_EQ(c(0.25), 0.5);
  EXPECT_DOUBLE_EQ(c(1.0), 2.0);
  EXPECT_DOUBLE_EQ(c(2.0), 0.5);  // halfway down 2 -> -1
  EXPECT_DOUBLE_EQ(c(3.0), -1.0);
  // Out of range: the end values (no extrapolation).
  EXPECT_DOUBLE_EQ(c(-5.0), 0.0);
  EXPECT_DOUBLE_EQ(c(3.5), -1.0);
  EXPECT_DOUBLE_EQ(c(1e9), -1.0);
  // Linear between points: the midpoint of every segment is the mean of its ends.
  for (std::size_t i = 1; i < c.points().size(); ++i) {
    const auto [t0, v0] = c.points()[i - 1];
    const auto [t1, v1] = c.points()[i];
    EXPECT_NEAR(c(0.5 * (t0 + t1)), 0.5 * (v0 + v1), 1e-15);
    EXPECT_NEAR(c(t0 + 0.1 * (t1 - t0)), v0 + 0.1 * (v1 - v0), 1e-15);
  }
}

TEST(SolverLoadCurve, DefaultsAndHelpers) {
  const LoadCurve one;
  EXPECT_DOUBLE_EQ(one(-1.0), 1.0);
  EXPECT_DOUBLE_EQ(one(7.0), 1.0);
  const LoadCurve k = LoadCurve::constant(0.3);
  EXPECT_DOUBLE_EQ(k(-2.0), 0.3);
  EXPECT_DOUBLE_EQ(k(2.0), 0.3);
  const LoadCurve r = LoadCurve::ramp(0.5, 1.5);
  EXPECT_DOUBLE_EQ(r(0.0), 0.0);
  EXPECT_DOUBLE_EQ(r(1.0), 0.5);
  EXPECT_DOUBLE_EQ(r(2.0), 1.0);
}

TEST(SolverLoadCurve, BadPointsAreRejected) {
  EXPECT_THROW(LoadCurve(std::vector<std::pair<double, double>>{}), std::invalid_argument);
  EXPECT_THROW(LoadCurve({{0.0, 0.0}, {0.0, 1.0}}), std::invalid_argument);  // repeated time
  EXPECT_THROW(LoadCurve({{1.0, 0.0}, {0.5, 1.0}}), std::invalid_argument);  // decreasing time
}

}  // namespace
}  // namespace stentsim::solver
