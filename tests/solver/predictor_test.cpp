// The stepper's predictor (each step starts from the last step's increment,
// extrapolated) and Newton's single assembly per full step: fewer Newton
// iterations, the same converged states, a reversing load detected, and one
// assembly per iteration when the full step is taken.
#include <gtest/gtest.h>

#include <cstdio>

#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/materials/presets.hpp"
#include "solver/nonlinear/load_stepper.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "solver/terms/robin_springs.hpp"
#include "tests/solver/neo_hooke_block.hpp"

namespace stentsim::solver {
namespace {

/// Counts the assemblies of the model it is added to (with and without tangent).
class CountingTerm : public Term {
 public:
  std::string name() const override { return "counter"; }
  void assemble(const SystemState&, Assembler& out) override {
    ++assemblies;
    if (out.wants_tangent()) ++tangent_assemblies;
  }
  int assemblies = 0, tangent_assemblies = 0;
};

struct Block {
  std::unique_ptr<NeoHookeBlock> block;
  Model& model;
  SolidBody* body;
  CountingTerm* counter;
};

// The block on springs at z = 0, follower pressure on z = 2 following `curve`.
std::unique_ptr<Block> make_block(double pressure, LoadCurve curve) {
  auto nb = make_neo_hooke_block(box_hex8(2, 2, 4, 1.0, 1.0, 2.0));
  nb->model.add_term<RobinSprings>("springs", *nb->body, nb->bottom, 100.0);
  nb->model.add_term<FollowerPressure>("pressure", *nb->body, nb->top, pressure, std::move(curve));
  CountingTerm& counter = nb->model.add_term<CountingTerm>();
  nb->model.size_constraints();
  SolidBody* body = nb->body;
  Model& model = nb->model;
  return std::make_unique<Block>(Block{std::move(nb), model, body, &counter});
}

struct StepperRun {
  Eigen::VectorXd u;
  int newton = 0, predicted = 0, steps = 0;
  std::vector<bool> predicted_at;  // per step
};

StepperRun run(Block& b, double t_end, double dt, bool predictor) {
  GlobalSystem sys(b.model.constraints);
  auto linear = make_linear_solver({});
  StepperRun r;
  r.u = Eigen::VectorXd::Zero(b.model.dofs.size());
  StepperSettings st;
  st.t_end = t_end;
  st.dt_initial = st.dt_max = dt;
  NewtonSettings ns;
  ns.residual_tolerance = 1e-11;
  ns.increment_tolerance = 1e-10;
  ns.predictor = predictor;
  run_load_steps(b.model, sys, *linear, r.u, st, ns, [&](const StepRecord& rec) {
    ++r.steps;
    r.newton += rec.newton_iterations;
    r.predicted += rec.predicted ? 1 : 0;
    r.predicted_at.push_back(rec.predicted);
  });
  return r;
}

TEST(SolverPredictor, FewerNewtonIterationsSameSolution) {
  auto with = make_block(0.15, LoadCurve::ramp(0, 1));
  auto without = make_block(0.15, LoadCurve::ramp(0, 1));
  const StepperRun a = run(*with, 1.0, 0.125, true), b = run(*without, 1.0, 0.125, false);
  std::printf("predictor: %d Newton iterations (%d of %d steps predicted); none: %d\n", a.newton, a.predicted, a.steps, b.newton);
  ASSERT_EQ(a.steps, 8);
  ASSERT_EQ(b.steps, 8);
  EXPECT_EQ(a.predicted, 7);  // every step but the first (no increment to extrapolate yet)
  EXPECT_EQ(b.predicted, 0);
  EXPECT_LT(a.newton, b.newton);
  EXPECT_LT((a.u - b.u).norm(), 1e-9 * b.u.norm());
}

TEST(SolverPredictor, AReversedLoadDropsTheGuess) {
  // Loaded to t = 1, unloaded to a fifth by t = 2: the first unloading step's guess points against the load.
  auto with = make_block(0.15, LoadCurve({{0.0, 0.0}, {1.0, 1.0}, {2.0, 0.2}}));
  auto without = make_block(0.15, LoadCurve({{0.0, 0.0}, {1.0, 1.0}, {2.0, 0.2}}));
  const StepperRun a = run(*with, 2.0, 0.25, true), b = run(*without, 2.0, 0.25, false);
  ASSERT_EQ(a.steps, 8);
  EXPECT_TRUE(a.predicted_at[3]);   // loading
  EXPECT_FALSE(a.predicted_at[4]);  // the first unloading step
  EXPECT_TRUE(a.predicted_at[5]);   // unloading goes on
  EXPECT_LT((a.u - b.u).norm(), 1e-9 * b.u.norm());
}

TEST(SolverPredictor, NoGuessForAStepThatPrescribedDofsDrive) {
  // The top pressed down by prescribed displacements (no pressure): the slope test would judge a
  // guess with the fixed DOFs at their old values, so no guess is made and the result is the same.
  auto with = make_block(0.0, LoadCurve::ramp(0, 1));
  auto without = make_block(0.0, LoadCurve::ramp(0, 1));
  for (Block* b : {with.get(), without.get()})
    for (std::size_t i = 0; i < b->body->num_nodes(); ++i)
      if (b->body->mesh().points[i].z() > 2 - 1e-9)
        b->model.constraints.fix(b->body->dof(i, 2), [](double t) { return -0.3 * t; });
  const StepperRun a = run(*with, 1.0, 0.25, true), b = run(*without, 1.0, 0.25, false);
  ASSERT_EQ(a.steps, 4);
  EXPECT_EQ(a.predicted, 0);
  EXPECT_EQ(a.newton, b.newton);
  EXPECT_LT((a.u - b.u).norm(), 1e-12 * b.u.norm());
}

TEST(SolverPredictor, TheTakenFullStepIsAssembledOnce) {
  // A small load: every Newton step is taken in full, so each iteration assembles once
  // (the full step with its tangent), plus the converged state's residual at the step's start.
  auto b = make_block(0.01, LoadCurve::ramp(0, 1));
  GlobalSystem sys(b->model.constraints);
  auto linear = make_linear_solver({});
  Eigen::VectorXd u = Eigen::VectorXd::Zero(b->model.dofs.size());
  NewtonSettings ns;
  ns.residual_tolerance = 1e-11;
  ns.increment_tolerance = 1e-10;
  const NewtonResult nr = newton_step(b->model, sys, *linear, u, 1.0, 1.0, ns);
  ASSERT_TRUE(nr.converged) << nr.failure;
  EXPECT_EQ(b->counter->assemblies, nr.iterations + 1);
  EXPECT_EQ(b->counter->tangent_assemblies, nr.iterations + 1);
}

}  // namespace
}  // namespace stentsim::solver
