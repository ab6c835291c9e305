// Assembly + Newton + adaptive stepping on small solids: quadratic
// convergence, agreement of all linear solvers, a patch test through the
// solver with prescribed boundary displacements, local-frame constraints.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/materials/presets.hpp"
#include "solver/nonlinear/load_stepper.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "solver/terms/robin_springs.hpp"
#include "tests/solver/neo_hooke_block.hpp"

namespace stentsim::solver {
namespace {

// The block on springs at z = 0, follower pressure on z = 2.
std::unique_ptr<NeoHookeBlock> make_block(MeshData mesh, double pressure) {
  auto b = make_neo_hooke_block(std::move(mesh));
  b->model.add_term<RobinSprings>("springs", *b->body, b->bottom, 100.0);
  b->model.add_term<FollowerPressure>("pressure", *b->body, b->top, pressure, LoadCurve::ramp(0, 1));
  b->model.size_constraints();
  return b;
}

TEST(SolverNewton, QuadraticConvergenceAndSolverAgreement) {
  std::vector<Eigen::VectorXd> results;
  for (const char* type : {"eigen_lu", "direct", "gmres_ilu", "gmres_amg"}) {
    auto b = make_block(box_hex8(3, 3, 6, 1.0, 1.0, 2.0), 0.15);
    GlobalSystem sys(b->model.constraints);
    LinearSolverSettings ls;
    ls.type = parse_linear_solver(type, "newton test");
    ls.tolerance = 1e-12;
    auto linear = make_linear_solver(ls);
    std::vector<std::pair<GlobalDof, Vec3>> nodes;
    for (std::size_t i = 0; i < b->body->num_nodes(); ++i) nodes.emplace_back(b->body->dof(i, 0), b->body->mesh().points[i]);
    linear->set_near_null_space(b->model.rigid_body_modes(nodes));
    Eigen::VectorXd u = Eigen::VectorXd::Zero(b->model.dofs.size());
    NewtonSettings ns;
    ns.residual_tolerance = 1e-12;
    ns.increment_tolerance = 1e-12;
    // One big step: compression of ~25 %, several Newton iterations.
    NewtonResult nr = newton_step(b->model, sys, *linear, u, 1.0, 1.0, ns);
    ASSERT_TRUE(nr.converged) << type << ": " << nr.failure;
    std::printf("%s: residuals", type);
    for (double r : nr.residual_norms) std::printf(" %.2e", r);
    std::printf("\n");
    const double top_uz = u(b->body->dof(b->body->num_nodes() - 1, 2));
    EXPECT_LT(top_uz, -0.2);
    // Quadratic convergence: in the last iterations, log r_{k+1} / log r_k ~ 2 (r scaled by r_0).
    const auto& r = nr.residual_norms;
    ASSERT_GE(r.size(), 4u);
    bool quadratic_seen = false;
    for (std::size_t k = 1; k + 1 < r.size(); ++k) {
      const double a = r[k] / r[0], c = r[k + 1] / r[0];
      if (a < 1e-2 && c > 1e-14) {
        const double rate = std::log(c) / std::log(a);
        std::printf("  rate at %zu: %.2f\n", k, rate);
        if (rate > 1.8) quadratic_seen = true;
      }
    }
    EXPECT_TRUE(quadratic_seen) << type;
    results.push_back(u);
  }
  for (std::size_t i = 1; i < results.size(); ++i)
    EXPECT_LT((results[i] - results[0]).norm(), 1e-8 * results[0].norm()) << i;
}

// Inexact Newton (Eisenstat-Walker forcing): on a Krylov solver the same state to
// the Newton tolerance with fewer linear iterations than solving each system to the
// fixed tolerance; the forcing term is asked of the solver, which a direct one refuses.
TEST(SolverNewton, InexactNewtonSavesKrylovIterations) {
  std::map<bool, NewtonResult> runs;
  std::map<bool, Eigen::VectorXd> states;
  for (bool inexact : {false, true}) {
    auto b = make_block(box_hex8(3, 3, 6, 1.0, 1.0, 2.0), 0.15);
    GlobalSystem sys(b->model.constraints);
    LinearSolverSettings ls;
    ls.type = LinearSolverType::gmres_ilu;
    ls.ilu_fill = 0;  // a weak preconditioner: many Krylov iterations per solve
    ls.tolerance = 1e-12;
    auto linear = make_linear_solver(ls);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(b->model.dofs.size());
    NewtonSettings ns;
    ns.residual_tolerance = 1e-10;
    ns.increment_tolerance = 1e-10;
    ns.inexact = inexact;
    runs[inexact] = newton_step(b->model, sys, *linear, u, 1.0, 1.0, ns);
    ASSERT_TRUE(runs[inexact].converged) << runs[inexact].failure;
    states[inexact] = u;
    std::printf("inexact %d: %d Newton, %d linear iterations\n", inexact, runs[inexact].iterations,
                runs[inexact].linear_iterations);
  }
  EXPECT_LT(runs[true].linear_iterations, 0.8 * runs[false].linear_iterations);
  EXPECT_LE(runs[true].iterations, runs[false].iterations + 2);
  EXPECT_LT((states[true] - states[false]).norm(), 1e-8 * states[false].norm());
  EXPECT_TRUE(make_linear_solver({.type = LinearSolverType::gmres_amg})->set_relative_tolerance(1e-3));
  EXPECT_FALSE(make_linear_solver({})->set_relative_tolerance(1e-3));
}

// A residual floor: forces that vary with u at a scale far below any Newton correction (a
// triangle wave of period 1e-9 mm on the top face's z DOFs) and that the tangent cannot see,
// as the kinks of element-based contact integration act on a sliding balloon. No iteration
// lowers |R| below the wave's amplitude; the floor test takes that state as converged when
// it is small against the forces in balance and no active set changes, and only then.
class ResidualFloorTerm : public Term {
 public:
  ResidualFloorTerm(std::vector<GlobalDof> dofs, double amplitude, bool unsettled)
      : dofs_(std::move(dofs)), amplitude_(amplitude), unsettled_(unsettled) {}
  std::string name() const override { return "floor"; }
  int accepted_changes() const override { return unsettled_ ? 1 : 0; }  // as a contact pair whose points still switch
  void assemble(const SystemState& state, Assembler& out) override {
    Eigen::VectorXd r(static_cast<Eigen::Index>(dofs_.size()));
    for (std::size_t i = 0; i < dofs_.size(); ++i) {
      const double x = state.u(dofs_[i]) / 1e-9;
      r(static_cast<Eigen::Index>(i)) = amplitude_ * (1.0 - 4.0 * std::abs(x - std::floor(x) - 0.5));
    }
    out.add(dofs_, r, Eigen::MatrixXd::Zero(r.size(), r.size()));
  }

 private:
  std::vector<GlobalDof> dofs_;
  double amplitude_;
  bool unsettled_;
};

TEST(SolverNewton, ResidualFloorIsTakenAsConvergedOnlyWhenSmallAgainstTheForcesAndSettled) {
  auto solve = [](double amplitude, double floor_tolerance, Eigen::VectorXd& u, bool unsettled = false) {
    auto b = make_neo_hooke_block(box_hex8(2, 2, 4, 1.0, 1.0, 2.0));
    b->model.add_term<RobinSprings>("springs", *b->body, b->bottom, 100.0);
    b->model.add_term<FollowerPressure>("pressure", *b->body, b->top, 0.1, LoadCurve::ramp(0, 1));
    std::vector<GlobalDof> top;
    for (std::size_t i = 0; i < b->body->num_nodes(); ++i)
      if (b->body->mesh().points[i].z() > 2 - 1e-9) top.push_back(b->body->dof(i, 2));
    if (amplitude > 0.0) b->model.add_term<ResidualFloorTerm>(top, amplitude, unsettled);
    b->model.size_constraints();
    GlobalSystem sys(b->model.constraints);
    auto linear = make_linear_solver({});
    u = Eigen::VectorXd::Zero(b->model.dofs.size());
    NewtonSettings ns;
    ns.residual_tolerance = 1e-12;
    ns.residual_absolute = 0.0;
    ns.increment_tolerance = 1e-12;
    ns.floor_tolerance = floor_tolerance;
    return newton_step(b->model, sys, *linear, u, 1.0, 1.0, ns);
  };
  Eigen::VectorXd clean, u;
  const double floor_tolerance = NewtonSettings{}.floor_tolerance;
  const NewtonResult smooth = solve(0.0, floor_tolerance, clean);
  ASSERT_TRUE(smooth.converged) << smooth.failure;
  EXPECT_FALSE(smooth.at_floor);  // a smooth model converges by its tolerances
  const double forces = smooth.force_magnitude;
  ASSERT_GT(forces, 0.0);
  // The wave's residual norm is about its amplitude times sqrt(9 nodes / 3) (mean square of a triangle wave).
  const double amplitude = 1e-2 * floor_tolerance * forces;
  const NewtonResult floored = solve(amplitude, floor_tolerance, u);
  ASSERT_TRUE(floored.converged) << floored.failure;
  EXPECT_TRUE(floored.at_floor);
  EXPECT_LT(floored.iterations, 12);
  std::printf("floor: |R| = %.2e of forces %.2e after %d iterations, |u - u_smooth| = %.2e of |u| %.2e\n",
              floored.residual_norms.back(), forces, floored.iterations, (u - clean).norm(), clean.norm());
  EXPECT_GT(floored.residual_norms.back(), 1e-12 * forces);  // above the residual tolerance: the floor test decided
  EXPECT_LT((u - clean).norm(), floor_tolerance * clean.norm());
  // Without the floor test, and with a floor above its tolerance, the step does not converge.
  EXPECT_FALSE(solve(amplitude, 0.0, u).converged);
  EXPECT_FALSE(solve(10.0 * floor_tolerance * forces, floor_tolerance, u).converged);
  // ... and while an active set keeps changing, the state is on its way, not at a floor.
  EXPECT_FALSE(solve(amplitude, floor_tolerance, u, true).converged);
}

// A floor the state creeps along: a residual the tangent cannot see that falls to 70 %
// at each accepted iterate (as the damped iterations of the patient example's deflation,
// 10-30 % less per iteration at 1e-6 of its forces). It is a floor with floor_reduction 0.5
// (the case's solve scene): each iteration keeps at least that fraction of |R|; with 0.8 it
// is progress, and the step runs out of iterations long before 0.7^k reaches the tolerance.
class CreepingFloorTerm : public Term {
 public:
  CreepingFloorTerm(std::vector<GlobalDof> dofs, double amplitude) : dofs_(std::move(dofs)), amplitude_(amplitude) {}
  std::string name() const override { return "creeping floor"; }
  void assemble(const SystemState&, Assembler& out) override {
    const Eigen::VectorXd r = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(dofs_.size()), amplitude_ * std::pow(0.7, accepted_));
    out.add(dofs_, r, Eigen::MatrixXd::Zero(r.size(), r.size()));
  }
  void accept() override { ++accepted_; }
  void begin_step(const SystemState&) override { accepted_ = 0; }  // each load step creeps anew

 private:
  std::vector<GlobalDof> dofs_;
  double amplitude_;
  int accepted_ = 0;
};

// The loaded block with a creeping floor of `amplitude` N on its top face's x DOFs (0.1 MPa
// on the 1 mm^2 top face: forces in balance of about 0.1 N), and Newton settings whose
// tolerances only the floor test can meet.
struct CreepingBlock {
  std::unique_ptr<NeoHookeBlock> b;
  std::unique_ptr<GlobalSystem> sys;
  std::unique_ptr<LinearSolver> linear;
  Eigen::VectorXd u;
  NewtonSettings ns;

  CreepingBlock(double amplitude, double floor_reduction) : b(make_neo_hooke_block(box_hex8(2, 2, 4, 1.0, 1.0, 2.0))) {
    b->model.add_term<RobinSprings>("springs", *b->body, b->bottom, 100.0);
    b->model.add_term<FollowerPressure>("pressure", *b->body, b->top, 0.1, LoadCurve::ramp(0, 1));
    std::vector<GlobalDof> top;
    for (std::size_t i = 0; i < b->body->num_nodes(); ++i)
      if (b->body->mesh().points[i].z() > 2 - 1e-9) top.push_back(b->body->dof(i, 0));
    b->model.add_term<CreepingFloorTerm>(top, amplitude);
    b->model.size_constraints();
    sys = std::make_unique<GlobalSystem>(b->model.constraints);
    linear = make_linear_solver({});
    u = Eigen::VectorXd::Zero(b->model.dofs.size());
    ns.residual_tolerance = 1e-12;
    ns.residual_absolute = 0.0;
    ns.increment_tolerance = 1e-12;
    ns.floor_tolerance = 1e-6;
    ns.floor_reduction = floor_reduction;
  }
};

TEST(SolverNewton, AResidualThatKeepsMoreThanFloorReductionIsAtItsFloor) {
  auto solve = [](double floor_reduction, double amplitude_of_forces) {
    CreepingBlock c(amplitude_of_forces * 0.1, floor_reduction);
    return newton_step(c.b->model, *c.sys, *c.linear, c.u, 1.0, 1.0, c.ns);
  };
  const NewtonResult crept = solve(0.5, 1e-7);
  ASSERT_TRUE(crept.converged) << crept.failure;
  EXPECT_TRUE(crept.at_floor);
  EXPECT_LT(crept.iterations, 10);
  const auto runs_out = [](const NewtonResult& r) {
    return !r.converged && r.failure.find("no convergence in") != std::string::npos;
  };
  EXPECT_TRUE(runs_out(solve(0.8, 1e-7)));  // 0.7 per iteration is progress by that rule
  EXPECT_TRUE(runs_out(solve(NewtonSettings{}.floor_reduction, 1e-7)));  // ... and by the default 0.9
  EXPECT_TRUE(runs_out(solve(0.5, 1e-2)));  // far above floor_tolerance: no floor in 20 iterations
}

// The stepper judges a step taken at the residual floor by the iterations that reached
// it: the floor_iterations that only confirmed it do not keep the step from growing.
// easy_iterations is set one below a floor step's count, which the step then exceeds.
TEST(SolverNewton, AStepAtTheFloorGrowsByTheIterationsThatReachedIt) {
  auto run = [](int easy_iterations) {
    CreepingBlock c(1e-8, 0.5);
    StepperSettings st;
    st.dt_initial = 0.1;
    st.dt_max = 1.0;
    st.easy_iterations = easy_iterations;
    std::vector<StepRecord> steps;
    run_load_steps(c.b->model, *c.sys, *c.linear, c.u, st, c.ns, [&](const StepRecord& r) { steps.push_back(r); });
    return steps;
  };
  const auto probe = run(100);
  ASSERT_GE(probe.size(), 2u);
  ASSERT_TRUE(probe[0].at_floor);
  const int n = probe[0].newton_iterations;
  ASSERT_GT(n, NewtonSettings{}.floor_iterations + 1);
  const auto steps = run(n - 1);
  ASSERT_GE(steps.size(), 2u);
  ASSERT_EQ(steps[0].newton_iterations, n);  // more than easy_iterations ...
  EXPECT_NEAR(steps[1].dt, 1.5 * steps[0].dt, 1e-12);  // ... and the step still grew
  // One below the iterations that reached the floor: not easy, the step keeps its size.
  const auto hard = run(n - NewtonSettings{}.floor_iterations - 1);
  ASSERT_GE(hard.size(), 2u);
  ASSERT_EQ(hard[0].newton_iterations, n);
  EXPECT_NEAR(hard[1].dt, hard[0].dt, 1e-12);
}

// Prescribed homogeneous deformation on the boundary of a distorted tet10
// patch: the solver reproduces it at the interior nodes.
TEST(SolverNewton, PatchTestThroughSolver) {
  MeshData mesh = tet4_to_tet10(hex8_to_tet4(box_hex8(2, 2, 2, 1, 1, 1)));
  mesh.points[13] += Vec3(0.07, -0.04, 0.05);
  Model model;
  SolidBodySpec spec;
  spec.name = "patch";
  spec.mesh = mesh;
  spec.materials = {material_preset("media")};
  for (auto& f : spec.materials[0].fibers) f.global_direction = Vec3(0, 1, 1);
  spec.materials[0].viscous.reset();
  spec.cell_material.assign(mesh.num_cells(), 0);
  auto& body = model.add_term<SolidBody>(spec, model.dofs.allocate("patch", 3 * static_cast<GlobalDof>(mesh.points.size())));
  model.size_constraints();
  Mat3 a;
  a << 0.2, 0.05, 0.0, -0.03, -0.1, 0.04, 0.02, 0.0, 0.15;
  for (std::size_t i = 0; i < body.num_nodes(); ++i) {
    const Vec3 p = body.mesh().points[i];
    if (p.minCoeff() > 1e-9 && p.maxCoeff() < 1 - 1e-9) continue;
    for (int c = 0; c < 3; ++c) {
      const double v = (a * p)(c);
      model.constraints.fix(body.dof(i, c), [v](double t) { return v * t; });
    }
  }
  GlobalSystem sys(model.constraints);
  auto linear = make_linear_solver({});
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
  StepperSettings st;
  st.dt_initial = 0.5;
  st.dt_max = 0.5;
  int steps = 0;
  run_load_steps(model, sys, *linear, u, st, {}, [&](const StepRecord&) { ++steps; });
  EXPECT_EQ(steps, 2);
  double err = 0.0;
  for (std::size_t i = 0; i < body.num_nodes(); ++i)
    err = std::max(err, (u.segment<3>(body.dof(i, 0)) - a * body.mesh().points[i]).norm());
  std::printf("patch through solver: max nodal error %.2e\n", err);
  EXPECT_LT(err, 1e-12);
}

// A node constrained to move only radially in a rotated frame: a ring
// sector whose nodes on both cut planes move only radially, inflated by
// pressure, stays axisymmetric (cut-plane nodes keep their angle).
TEST(SolverNewton, RadialFrameConstraint) {
  const double angle = 0.7;  // not aligned with any axis
  MeshData mesh = ring_sector_hex8(1.0, 1.3, angle, 0.1, 2, 6, 1);
  Model model;
  SolidBodySpec spec;
  spec.name = "ring";
  spec.mesh = mesh;
  Material m;
  m.name = "nh";
  m.matrix = CoupledNeoHooke::from_young_poisson(1.0, 0.45);
  spec.materials = {m};
  spec.cell_material.assign(mesh.num_cells(), 0);
  auto& body = model.add_term<SolidBody>(spec, model.dofs.allocate("ring", 3 * static_cast<GlobalDof>(mesh.points.size())));
  std::vector<fem::Face> inner;
  for (const auto& f : fem::boundary_faces(body.mesh())) {
    bool all = true;
    for (int i = 0; i < f.count; ++i) all = all && body.mesh().points[static_cast<std::size_t>(f.nodes[i])].head<2>().norm() < 1 + 1e-9;
    if (all) inner.push_back(f);
  }
  model.add_term<FollowerPressure>("p", body, inner, 0.05, LoadCurve::ramp(0, 1));
  model.size_constraints();
  for (std::size_t i = 0; i < body.num_nodes(); ++i) {
    const Vec3 p = body.mesh().points[i];
    model.constraints.fix(body.dof(i, 2), [](double) { return 0.0; });  // plane strain
    const double th = std::atan2(p.y(), p.x());
    if (std::abs(th) < 1e-9 || std::abs(th - angle) < 1e-9) {
      Mat3 q;
      q.col(0) = Vec3(std::cos(th), std::sin(th), 0);
      q.col(1) = Vec3(-std::sin(th), std::cos(th), 0);
      q.col(2) = Vec3::UnitZ();
      model.constraints.set_frame(body.dof(i, 0), q);
      model.constraints.fix(body.dof(i, 1), [](double) { return 0.0; });  // circumferential
    }
  }
  GlobalSystem sys(model.constraints);
  auto linear = make_linear_solver({});
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
  StepperSettings st;
  st.dt_initial = 0.25;
  run_load_steps(model, sys, *linear, u, st, {}, [](const StepRecord&) {});
  // Every node keeps its angle and nodes at equal reference radius move equally.
  double angle_err = 0.0, spread = 0.0;
  std::map<long, std::pair<double, double>> by_radius;
  for (std::size_t i = 0; i < body.num_nodes(); ++i) {
    const Vec3 p = body.mesh().points[i], x = body.position(u, i);
    angle_err = std::max(angle_err, std::abs(std::atan2(x.y(), x.x()) - std::atan2(p.y(), p.x())));
    auto& [lo, hi] = by_radius.try_emplace(std::lround(p.head<2>().norm() * 1e6), 1e9, -1e9).first->second;
    lo = std::min(lo, x.head<2>().norm());
    hi = std::max(hi, x.head<2>().norm());
  }
  for (auto& [k, v] : by_radius) spread = std::max(spread, v.second - v.first);
  EXPECT_LT(angle_err, 1e-10);
  EXPECT_LT(spread, 1e-10);
  EXPECT_GT(body.position(u, 0).head<2>().norm(), 1.01);
}

}  // namespace
}  // namespace stentsim::solver
