// The contact active set counts changes between accepted Newton iterates only:
// a line-search trial assembled with its tangent and then rejected adds none.
#include <gtest/gtest.h>

#include "solver/contact/active_set.hpp"

namespace stentsim::solver::contact {
namespace {

TEST(ContactActiveSet, ARejectedTrialIsNoChange) {
  ActiveSet s;
  s.resize(2);
  s.begin_step();
  EXPECT_EQ(s.evaluate(0, true), 1);  // the full step: point 0 would enter contact ...
  EXPECT_EQ(s.evaluate(0, false), 0);  // ... but the accepted (shorter) step leaves it out
  s.accept();
  EXPECT_EQ(s.evaluate(0, false), 0);
  EXPECT_EQ(s.evaluate(0, true), 1);
  s.accept();                          // now it entered: one change
  EXPECT_EQ(s.evaluate(0, false), 2);  // leaving again would be the second
  s.accept();
  EXPECT_EQ(s.evaluate(1, false), 0);  // the other point never changed
  s.commit(1, 0, 1);
  EXPECT_FALSE(s.committed(0));
  s.begin_step();
  EXPECT_EQ(s.evaluate(0, true), 1);  // a new step counts afresh
}

TEST(ContactActiveSet, CommitTakesTheLastEvaluationAndRollbackReturnsToIt) {
  ActiveSet s;
  s.resize(1);
  s.evaluate(0, true);
  s.commit(1, 0, 1);  // converged without an accept (a test assembling the pair by hand)
  EXPECT_TRUE(s.committed(0));
  s.evaluate(0, false);
  s.accept();
  s.rollback();
  s.begin_step();  // the stepper's next attempt
  EXPECT_TRUE(s.committed(0));
  EXPECT_EQ(s.evaluate(0, true), 0);  // the iterate is the committed state again
}

}  // namespace
}  // namespace stentsim::solver::contact
