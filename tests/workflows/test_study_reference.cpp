// The tube reference of the error study (workflows/study/references/
// tube_reference.hpp): plane-strain coupled neo-Hooke under follower
// pressure, shooting with Dormand-Prince + Newton (issue 11).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "workflows/study/references/tube_reference.hpp"

using stentsim::study::reference::PlaneStrainTube;

// At p = 1e-5 E the strains are ~1e-5, so the nonlinear solution equals the
// small-strain plane-strain Lame displacement to 1e-4 relative (issue 11).
TEST(StudyTubeReference, SmallPressureEqualsPlaneStrainLame) {
  for (double nu : {0.0, 0.3, 0.45, 0.49}) {
    const double E = 1.0;
    const auto t = PlaneStrainTube::from_young(E, nu, 0.8, 1.4);
    const double p = 1e-5 * E;
    const double u = t.inner_radius(p) - 0.8;
    // Lame from E and nu directly (not from c, beta), so a wrong mapping fails.
    const double mu = E / (2 * (1 + nu)), lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    const double a2 = 0.64, b2 = 1.96;
    const double lame = p * a2 / (2 * (lambda + mu) * (b2 - a2)) * 0.8 + p * a2 * b2 / (2 * mu * (b2 - a2)) / 0.8;
    EXPECT_NEAR(u / lame, 1.0, 1e-4) << "nu = " << nu;
    EXPECT_GT(std::abs(u / lame - 1.0), 1e-8) << "nonlinear effect should be visible at 1e-5 strain";
  }
}

// The fixed-step RK4 + bisection solution that the solver's tube test used
// before (1.176890 mm for the example scene, examples/tube_inflation.yaml),
// and the residual of the returned radius is zero to round-off.
TEST(StudyTubeReference, ExampleSceneValueAndResidual) {
  const auto t = PlaneStrainTube::from_young(1.0, 0.45, 0.8, 1.4);
  const double r = t.inner_radius(0.12);
  EXPECT_NEAR(r, 1.1768896377, 1e-9);
  EXPECT_NEAR(t.outer_traction(0.12, r), 0.0, 1e-11);
  // Inverse problem returns the pressure back.
  EXPECT_NEAR(t.pressure_at(r, 0.05, 0.2), 0.12, 1e-9);
}

// The asymptotic pressure tends to the incompressible plane-strain limit
// mu ln(B/A) as nu -> 1/2; above it no equilibrium exists and the reference
// says so instead of returning a number.
TEST(StudyTubeReference, AsymptoticPressureAndNoEquilibriumAbove) {
  const auto t45 = PlaneStrainTube::from_young(1.0, 0.45, 0.8, 1.4);
  const auto t49 = PlaneStrainTube::from_young(1.0, 0.49, 0.8, 1.4);
  const double pa45 = t45.asymptotic_pressure(), pa49 = t49.asymptotic_pressure();
  const double limit49 = 1.0 / (2 * 1.49) * std::log(1.4 / 0.8);
  EXPECT_NEAR(pa49 / limit49, 1.0, 0.01);
  EXPECT_GT(pa45, 0.12);
  EXPECT_THROW(t45.inner_radius(1.5 * pa45), std::runtime_error);
  EXPECT_NO_THROW(t45.inner_radius(0.9 * pa45));
}
