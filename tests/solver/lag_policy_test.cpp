// The preconditioner lagging rule (solver/linalg/lag_policy.hpp): the extra
// GMRES time of lagged solves, judged against the fresh preconditioner's rate,
// is summed until it reaches the set-up's cost.
#include <gtest/gtest.h>

#include <cmath>

#include "solver/linalg/lag_policy.hpp"

using stentsim::solver::LagPolicy;

TEST(LagPolicy, NothingToLagBeforeTheFirstSetUp) {
  LagPolicy p;
  EXPECT_FALSE(p.may_lag());
  EXPECT_EQ(p.iteration_cap(1e-6, 2000), 2000);
}

TEST(LagPolicy, ExtraIterationsAreChargedUntilTheyPayForASetUp) {
  LagPolicy p;
  // Set-up 1 s; its first solve reached 1e-6 in 10 iterations (rho0 = 10^-0.6) in 1 s.
  p.built(1.0, 10, 1e-6, 1.0);
  EXPECT_TRUE(p.may_lag());
  // A lagged solve to 1e-6 in 12 iterations, 0.1 s each: 2 extra iterations, 0.2 s.
  for (int k = 0; k < 4; ++k) {
    p.lagged(12, 1e-6, 1.2);
    EXPECT_NEAR(p.extra_seconds(), 0.2 * (k + 1), 1e-12);
    EXPECT_TRUE(p.may_lag()) << k;
  }
  p.lagged(13, 1e-6, 1.3);  // 3 extra: 1.1 s in all
  EXPECT_NEAR(p.extra_seconds(), 1.1, 1e-12);
  EXPECT_FALSE(p.may_lag()) << "1 s of extra iterations pays for a set-up";
  // A new set-up starts the account again.
  p.built(2.0, 20, 1e-6, 2.0);
  EXPECT_TRUE(p.may_lag());
  EXPECT_EQ(p.extra_seconds(), 0.0);
}

TEST(LagPolicy, AnotherToleranceIsJudgedAtTheNearestDecadesFreshRate) {
  LagPolicy p;
  p.built(1.0, 10, 1e-6, 1.0);
  // Only the 1e-6 decade has a rate: to 1e-2 a fresh solve would need 10 * 2/6 = 3.33
  // iterations, so 4 are 0.67 extra.
  p.lagged(4, 1e-2, 0.4);
  EXPECT_NEAR(p.extra_seconds(), (4.0 - 10.0 / 3.0) * 0.1, 1e-12);
  // Fewer iterations than the fresh rate predicts cost nothing.
  p.lagged(2, 1e-3, 0.2);
  EXPECT_NEAR(p.extra_seconds(), (4.0 - 10.0 / 3.0) * 0.1, 1e-12);
  // A fresh solve to 1e-2 in 5 iterations: that decade's own rate from then on, the 1e-6
  // decade keeps its own (deep solves converge more slowly per iteration).
  p.built(1.0, 5, 1e-2, 0.5);
  p.lagged(6, 1e-2, 0.6);
  EXPECT_NEAR(p.extra_seconds(), 0.1, 1e-12);
  p.lagged(12, 1e-6, 1.2);
  EXPECT_NEAR(p.extra_seconds(), 0.1 + 0.2, 1e-12);
  // The nearest decade with a rate: 1e-3 lies nearer 1e-2's decade than 1e-6's.
  p.lagged(2, 1e-3, 0.2);  // 1e-2's rate: 7.5 iterations for 1e-3, so none extra
  EXPECT_NEAR(p.extra_seconds(), 0.3, 1e-12);
}

TEST(LagPolicy, TheIterationCapIsTheFreshCountPlusWhatTheSetUpBuys) {
  LagPolicy p;
  p.built(1.0, 10, 1e-6, 1.0);  // 0.1 s per iteration: a set-up buys 10
  EXPECT_EQ(p.iteration_cap(1e-6, 2000), 10 + 10 + 1);
  EXPECT_EQ(p.iteration_cap(1e-6, 15), 15);
  p.lagged(15, 1e-6, 1.5);  // 0.5 s spent
  EXPECT_EQ(p.iteration_cap(1e-6, 2000), 10 + 5 + 1);
}

TEST(LagPolicy, ASolveWithoutIterationsGivesNoRateToLagOn) {
  LagPolicy p;
  p.built(1.0, 0, 0.0, 0.0);  // a zero right-hand side
  EXPECT_FALSE(p.may_lag());
  p.built(1.0, 5, 1.0, 0.5);  // no reduction at all
  EXPECT_FALSE(p.may_lag());
}
