// MueLu SA-AMG on a system large enough to be coarsened (the coarse size is
// 1000 unknowns): a hex8 block of neo-Hooke elasticity with 7.6k DOFs, AMG-GMRES
// against the direct solution, with the hierarchy's level count checked. And
// the near-null-space checks: a null space that does not describe the system
// (wrong row count, rows zero in every mode, unknowns not in blocks of 3) is
// an InputError, not silently dropped.
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <filesystem>
#include <unistd.h>
#include <cstdio>

#include "common/error.hpp"
#include "common/summary.hpp"
#include "solver/app/solve.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/linalg/linear_solver.hpp"
#include "solver/nonlinear/load_stepper.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "solver/terms/robin_springs.hpp"

namespace stentsim::solver {
namespace {

struct Problem {
  Model model;
  SolidBody* body = nullptr;
  CsrMatrix k;
  Eigen::VectorXd rhs;
  Eigen::MatrixXd modes;
};

// n x n x 2n hex8 block (1 x 1 x 2 mm), neo-Hooke E = 1 MPa, nu = 0.3, clamped
// by springs at z = 0, pressure 0.01 MPa on z = 2: the first Newton system.
std::unique_ptr<Problem> block_system(int n) {
  auto p = std::make_unique<Problem>();
  SolidBodySpec spec;
  spec.name = "block";
  spec.mesh = box_hex8(n, n, 2 * n, 1.0, 1.0, 2.0);
  Material m;
  m.name = "nh";
  m.matrix = CoupledNeoHooke::from_young_poisson(1.0, 0.3);
  spec.materials = {m};
  spec.cell_material.assign(spec.mesh.num_cells(), 0);
  p->body = &p->model.add_term<SolidBody>(spec, p->model.dofs.allocate("block", 3 * static_cast<GlobalDof>(spec.mesh.points.size())));
  std::vector<fem::Face> bottom, top;
  for (const auto& f : fem::boundary_faces(p->body->mesh())) {
    double zmin = 1e9, zmax = -1e9;
    for (int i = 0; i < f.count; ++i) {
      const double z = p->body->mesh().points[static_cast<std::size_t>(f.nodes[i])].z();
      zmin = std::min(zmin, z), zmax = std::max(zmax, z);
    }
    if (zmax < 1e-9) bottom.push_back(f);
    if (zmin > 2 - 1e-9) top.push_back(f);
  }
  p->model.add_term<RobinSprings>("springs", *p->body, bottom, 100.0);
  p->model.add_term<FollowerPressure>("pressure", *p->body, top, 0.01, LoadCurve::ramp(0, 1));
  p->model.size_constraints();
  GlobalSystem sys(p->model.constraints);
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(p->model.dofs.size());
  p->model.assemble(u, 1.0, 1.0, Eigen::VectorXd::Zero(p->model.dofs.size()), sys);
  p->k = sys.matrix();
  p->rhs = sys.rhs();
  std::vector<std::pair<GlobalDof, Vec3>> nodes;
  for (std::size_t i = 0; i < p->body->num_nodes(); ++i) nodes.emplace_back(p->body->dof(i, 0), p->body->mesh().points[i]);
  p->modes = p->model.rigid_body_modes(nodes);
  return p;
}

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

TEST(SolverAmg, CoarsensSevenThousandDofsAndMatchesDirect) {
  auto p = block_system(10);  // 11 x 11 x 21 nodes = 7,623 DOFs
  ASSERT_GT(p->k.rows, 7000);
  LinearSolverSettings direct;
  direct.type = LinearSolverType::eigen_lu;  // SparseLU (COLAMD): the serial reference
  Eigen::VectorXd x_direct;
  auto t0 = std::chrono::steady_clock::now();
  const LinearSolveStats sd = make_linear_solver(direct)->solve(p->k, p->rhs, x_direct);
  const double t_direct = since(t0);
  ASSERT_TRUE(sd.converged);

  LinearSolverSettings amg;
  amg.type = LinearSolverType::gmres_amg;
  amg.tolerance = 1e-10;
  auto solver = make_linear_solver(amg);
  solver->set_near_null_space(p->modes);
  Eigen::VectorXd x_amg;
  t0 = std::chrono::steady_clock::now();
  const LinearSolveStats sa = solver->solve(p->k, p->rhs, x_amg);
  const double t_amg = since(t0);
  const double diff = (x_amg - x_direct).norm() / x_direct.norm();
  std::printf("%lld DOFs: direct %.2f s; AMG-GMRES %d levels, %d iterations, residual %.2e, %.2f s (setup %.2f s); "
              "|x_amg - x_direct| / |x_direct| = %.2e\n",
              static_cast<long long>(p->k.rows), t_direct, sa.amg_levels, sa.iterations, sa.relative_residual, t_amg,
              sa.setup_seconds, diff);
  EXPECT_TRUE(sa.converged);
  EXPECT_GE(sa.amg_levels, 2) << "MueLu did not coarsen (coarse size 1000)";
  EXPECT_LT(sa.relative_residual, 1e-10);
  EXPECT_LT(diff, 1e-8);
  // With the rigid-body near-null space a multigrid cycle is a good preconditioner:
  // far fewer iterations than unknowns (a broken hierarchy needs hundreds).
  EXPECT_LT(sa.iterations, 60);
  EXPECT_EQ(sd.amg_levels, 0);
  // The near-null space is used: without it MueLu takes the 3 translations only
  // (no rotations in the coarse space) and GMRES needs more iterations.
  auto plain = make_linear_solver(amg);
  Eigen::VectorXd x_plain;
  const LinearSolveStats sp = plain->solve(p->k, p->rhs, x_plain);
  std::printf("without the rotation modes: %d levels, %d iterations\n", sp.amg_levels, sp.iterations);
  EXPECT_TRUE(sp.converged);
  EXPECT_LT(sa.iterations, sp.iterations) << "the rigid-body modes did not reach MueLu";
}

TEST(SolverAmg, SmallSystemIsOneLevel) {
  auto p = block_system(3);  // 4 x 4 x 7 nodes = 336 DOFs: below the coarse size
  LinearSolverSettings amg;
  amg.type = LinearSolverType::gmres_amg;
  auto solver = make_linear_solver(amg);
  solver->set_near_null_space(p->modes);
  Eigen::VectorXd x;
  const LinearSolveStats s = solver->solve(p->k, p->rhs, x);
  EXPECT_TRUE(s.converged);
  EXPECT_EQ(s.amg_levels, 1);
}

TEST(SolverAmg, NearNullSpaceMismatchIsAnError) {
  auto p = block_system(3);
  LinearSolverSettings amg;
  amg.type = LinearSolverType::gmres_amg;
  Eigen::VectorXd x;
  {  // too few rows (e.g. built before further DOFs were allocated)
    auto solver = make_linear_solver(amg);
    solver->set_near_null_space(p->modes.topRows(p->modes.rows() - 3));
    try {
      solver->solve(p->k, p->rhs, x);
      ADD_FAILURE() << "a near-null space with the wrong row count was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("rows but the system has"), std::string::npos) << e.what();
    }
  }
  {  // a node the modes do not describe (beam or multiplier DOFs left at zero)
    auto solver = make_linear_solver(amg);
    Eigen::MatrixXd modes = p->modes;
    modes.middleRows(30, 3).setZero();
    solver->set_near_null_space(modes);
    try {
      solver->solve(p->k, p->rhs, x);
      ADD_FAILURE() << "a near-null space with zero rows was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("unknown 30 is zero in every near-null-space mode"), std::string::npos) << e.what();
    }
  }
  {  // unknowns not in blocks of 3: the system with one extra (multiplier-like) row
    CsrMatrix k = p->k;
    k.rows += 1;
    k.cols.push_back(k.rows - 1);
    k.values.push_back(1.0);
    k.row_ptr.push_back(static_cast<std::int64_t>(k.cols.size()));
    Eigen::VectorXd b = Eigen::VectorXd::Zero(k.rows);
    b.head(p->rhs.size()) = p->rhs;
    auto solver = make_linear_solver(amg);
    EXPECT_THROW(solver->solve(k, b, x), InputError);
  }
}

TEST(SolverAmg, ScenesChooseIt) {
  const std::filesystem::path examples = std::filesystem::path(STENTSIM_TEST_SOURCE_DIR) / "examples";
  const auto out = std::filesystem::temp_directory_path() / ("stentsim_amg_scene_" + std::to_string(::getpid()));
  // A solid scene: the same QoI as with the direct solver.
  double r[2];
  int k = 0;
  for (const char* type : {"direct", "gmres_amg"}) {
    SolveOptions o;
    o.output_dir = out / type;
    o.linear_solver = parse_linear_solver(type, "test");
    ASSERT_EQ(solve_scene(examples / "tube_inflation.yaml", o), 0) << type;
    r[k++] = std::get<double>(Summary::read(out / type / "summary.yaml").qois().at("inner_radius_at_pmax").value);
  }
  EXPECT_NEAR(r[1], r[0], 1e-9);
  // Beam bodies (6-9 DOFs per node, multipliers): refused with the scene's file and key, not left to a wrong coarse space.
  SolveOptions o;
  o.output_dir = out / "ring";
  o.linear_solver = solver::LinearSolverType::gmres_amg;
  try {
    solve_scene(examples / "stent_ring_expansion.yaml", o);
    ADD_FAILURE() << "gmres_amg accepted a beam scene";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("stent_ring_expansion.yaml: solver.linear.type: gmres_amg"), std::string::npos) << m;
    EXPECT_NE(m.find("is a beam body"), std::string::npos) << m;
  }
  std::filesystem::remove_all(out);
}

// gmres_amg_block on a beam + solid contact scene (AMG on the balloon, LU on the
// ring) and gmres_lu (the whole matrix's LU, lagged): the direct solver's QoIs,
// through contact coming in and out of reach (the kept hierarchy and the kept
// factors meet newly filled contact entries there).
TEST(SolverAmg, BlockPreconditionerOnBeamContactSceneMatchesDirect) {
  const std::filesystem::path examples = std::filesystem::path(STENTSIM_TEST_SOURCE_DIR) / "examples";
  const auto out = std::filesystem::temp_directory_path() / ("stentsim_amg_block_" + std::to_string(::getpid()));
  std::map<std::string, double> q[3];
  int k = 0;
  for (const char* type : {"direct", "gmres_amg_block", "gmres_lu"}) {
    SolveOptions o;
    o.output_dir = out / type;
    o.linear_solver = parse_linear_solver(type, "test");
    ASSERT_EQ(solve_scene(examples / "contact_ring_on_balloon.yaml", o), 0) << type;
    for (const char* name : {"D_max", "D_end", "recoil_percent", "contact_force_stent_balloon_max"})
      q[k][name] = std::get<double>(Summary::read(out / type / "summary.yaml").qois().at(name).value);
    ++k;
  }
  for (int j : {1, 2})
    for (const auto& [name, v] : q[0]) EXPECT_NEAR(q[j][name], v, 1e-7 * std::abs(v)) << name << " with solver " << j;
  EXPECT_GT(q[0]["contact_force_stent_balloon_max"], 1.0);  // the ring was pushed by contact
  // A scene with one solid body and nothing else has no second block.
  SolveOptions o;
  o.output_dir = out / "tube";
  o.linear_solver = LinearSolverType::gmres_amg_block;
  try {
    solve_scene(examples / "tube_inflation.yaml", o);
    ADD_FAILURE() << "gmres_amg_block accepted a scene with one block";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no second block; use gmres_amg"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace stentsim::solver
