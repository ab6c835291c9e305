// What the linear solvers keep between Newton iterations while the matrix
// pattern stays, and that they drop it when the pattern grows (contact adds
// couplings):
// - "direct" (UMFPACK sparse LU, solver/linalg/umfpack_solver.cpp): the
//   symbolic analysis; non-symmetric systems solved to round-off; a singular
//   matrix reported, never returned as a solution;
// - "gmres_ilu" on one rank: the Tpetra matrix and RILUK's symbolic
//   factorization, refilled and recomputed (a stale preconditioner would still
//   converge, so the test compares GMRES iteration counts with a fresh solver);
// - "gmres_amg" on one rank: the Tpetra matrix and MueLu's prolongators;
// - lagging (LagPolicy): gmres_amg's and gmres_amg_block's preconditioners and
//   gmres_lu's whole-matrix LU serve later matrices, each solved to the tolerance.
#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cstdio>
#include <random>

#include "solver/linalg/linear_solver.hpp"

using namespace stentsim::solver;

namespace {

// A 3D Laplacian-like 7-point stencil on an n^3 grid plus a non-symmetric
// convection part (like the follower-pressure tangent): diagonally dominant.
// wx, wz weight the couplings along x and z (anisotropy; 1: isotropic).
CsrMatrix grid_matrix(int n, double skew, bool extra_coupling = false, double wx = 1.0, double wz = 1.0) {
  CsrMatrix a;
  a.rows = static_cast<std::int64_t>(n) * n * n;
  a.row_ptr = {0};
  auto id = [n](int i, int j, int k) { return static_cast<std::int64_t>((k * n + j) * n + i); };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        std::vector<std::pair<std::int64_t, double>> row;
        row.emplace_back(id(i, j, k), 2.0 * (wx + 1.0 + wz) + 0.5);
        if (i > 0) row.emplace_back(id(i - 1, j, k), -wx - skew);
        if (i + 1 < n) row.emplace_back(id(i + 1, j, k), -wx + skew);
        if (j > 0) row.emplace_back(id(i, j - 1, k), -1.0);
        if (j + 1 < n) row.emplace_back(id(i, j + 1, k), -1.0);
        if (k > 0) row.emplace_back(id(i, j, k - 1), -wz);
        if (k + 1 < n) row.emplace_back(id(i, j, k + 1), -wz);
        // A long-range coupling between the first and last unknowns (a new contact pair).
        if (extra_coupling && id(i, j, k) == 0) row.emplace_back(a.rows - 1, 0.3);
        if (extra_coupling && id(i, j, k) == a.rows - 1) row.emplace_back(0, -0.2);
        std::sort(row.begin(), row.end());
        for (const auto& [c, v] : row) a.cols.push_back(c), a.values.push_back(v);
        a.row_ptr.push_back(static_cast<std::int64_t>(a.cols.size()));
      }
  return a;
}

// Scalar AMG (constant near-null space) solved to 1e-10, for the grid matrices;
// `lag`: the preconditioner may be lagged (the tests of what a set-up keeps set it
// up for every matrix).
LinearSolverSettings scalar_amg(LinearSolverType type, bool lag = false) {
  LinearSolverSettings s;
  s.type = type;
  s.amg_equations_per_node = 1;
  s.tolerance = 1e-10;
  s.lag_preconditioner = lag;
  return s;
}

Eigen::VectorXd eigen_lu_solution(const CsrMatrix& a, const Eigen::VectorXd& b) {
  Eigen::VectorXd x;
  make_eigen_lu_solver()->solve(a, b, x);
  return x;
}

}  // namespace

TEST(Umfpack, SolvesNonSymmetricSystemsToRoundOff) {
  const CsrMatrix a = grid_matrix(12, 0.4);
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> d(-1, 1);
  Eigen::VectorXd b(a.rows);
  for (auto& v : b) v = d(gen);
  Eigen::VectorXd x;
  auto solver = make_umfpack_solver();
  const auto stats = solver->solve(a, b, x);
  ASSERT_TRUE(stats.converged);
  EXPECT_LT(stats.relative_residual, 1e-13);
  EXPECT_LT((a.multiply(x) - b).norm() / b.norm(), 1e-13);
  // Not the transpose (the CSR arrays are A' as compressed columns): with a
  // skew part the transposed system's solution differs clearly.
  EXPECT_LT((x - eigen_lu_solution(a, b)).norm() / x.norm(), 1e-12);
}

TEST(Umfpack, ReusesTheAnalysisForNewValuesAndRedoesItForANewPattern) {
  auto solver = make_umfpack_solver();
  Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(1000, -1, 2), x;
  // Same pattern, new values (the next Newton iteration).
  for (double skew : {0.1, 0.45, -0.3}) {
    const CsrMatrix a = grid_matrix(10, skew);
    ASSERT_TRUE(solver->solve(a, b, x).converged);
    EXPECT_LT((a.multiply(x) - b).norm() / b.norm(), 1e-13) << "skew " << skew;
  }
  // A grown pattern (a coupling the analysis has not seen): must not reuse it.
  const CsrMatrix grown = grid_matrix(10, 0.2, true);
  ASSERT_TRUE(solver->solve(grown, b, x).converged);
  EXPECT_LT((grown.multiply(x) - b).norm() / b.norm(), 1e-13);
  // And back to the smaller pattern.
  const CsrMatrix small = grid_matrix(10, 0.2);
  ASSERT_TRUE(solver->solve(small, b, x).converged);
  EXPECT_LT((small.multiply(x) - b).norm() / b.norm(), 1e-13);
}

TEST(Umfpack, ASingularMatrixIsAnErrorNotASolution) {
  CsrMatrix a = grid_matrix(5, 0.0);
  // Zero the last row's values: a DOF nothing holds.
  for (auto k = a.row_ptr[static_cast<std::size_t>(a.rows) - 1]; k < a.row_ptr.back(); ++k) a.values[static_cast<std::size_t>(k)] = 0.0;
  Eigen::VectorXd b = Eigen::VectorXd::Ones(a.rows), x;
  try {
    make_umfpack_solver()->solve(a, b, x);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("singular"), std::string::npos) << e.what();
  }
}

TEST(Umfpack, TheDirectSolverOnOneRankIsUmfpack) {
  LinearSolverSettings s;
  s.type = LinearSolverType::direct;
  const auto solver = make_linear_solver(s);
  EXPECT_NE(solver->describe().find("UMFPACK"), std::string::npos) << solver->describe();
  const CsrMatrix a = grid_matrix(8, 0.3);
  Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(a.rows, 0, 1), x;
  ASSERT_TRUE(solver->solve(a, b, x).converged);
  EXPECT_LT((a.multiply(x) - b).norm() / b.norm(), 1e-13);
}

TEST(IluReuse, RefilledMatrixAndRecomputedIluMatchAFreshSolver) {
  LinearSolverSettings s;
  s.type = LinearSolverType::gmres_ilu;
  s.ilu_fill = 1;  // an inexact ILU, so the preconditioner's values matter
  s.tolerance = 1e-10;
  s.lag_preconditioner = false;
  const auto kept = make_linear_solver(s);
  Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(1728, -1, 2);
  int differing_iterations = 0, previous = -1;
  for (const auto& [skew, grown] : std::vector<std::pair<double, bool>>{{0.05, false}, {0.9, false}, {-0.6, false}, {0.3, true}, {0.95, true}, {0.1, false}}) {
    CsrMatrix a = grid_matrix(12, skew, grown);
    Eigen::VectorXd x_kept, x_fresh;
    const auto st_kept = kept->solve(a, b, x_kept);
    const auto st_fresh = make_linear_solver(s)->solve(a, b, x_fresh);
    ASSERT_TRUE(st_kept.converged && st_fresh.converged) << "skew " << skew;
    EXPECT_EQ(st_kept.iterations, st_fresh.iterations) << "skew " << skew << (grown ? " (grown pattern)" : "");
    EXPECT_LT((x_kept - x_fresh).norm() / x_fresh.norm(), 1e-8) << "skew " << skew;
    EXPECT_LT((a.multiply(x_kept) - b).norm() / b.norm(), 1e-9) << "skew " << skew;
    if (previous >= 0 && st_fresh.iterations != previous) ++differing_iterations;
    previous = st_fresh.iterations;
  }
  // The matrices differ enough that a preconditioner of the previous values
  // would change the iteration count (else the comparison above proves nothing).
  EXPECT_GE(differing_iterations, 2);
}

// The Tpetra matrix is made from the CSR arrays directly when every row's columns
// increase; a matrix whose rows do not (not GlobalSystem's, but the solvers take any
// CSR) is inserted entry by entry. Both give the same operator: each solve is checked
// against its own matrix and against the same system in sorted order.
TEST(TpetraMatrix, RowsInAnyColumnOrderGiveTheSameOperator) {
  LinearSolverSettings s;
  s.type = LinearSolverType::gmres_ilu;
  s.tolerance = 1e-12;
  s.lag_preconditioner = false;
  const CsrMatrix sorted = grid_matrix(8, 0.4, true);
  CsrMatrix shuffled = sorted;
  for (std::int64_t i = 0; i < shuffled.rows; i += 3) {  // every third row reversed
    const auto b = static_cast<std::ptrdiff_t>(shuffled.row_ptr[static_cast<std::size_t>(i)]);
    const auto e = static_cast<std::ptrdiff_t>(shuffled.row_ptr[static_cast<std::size_t>(i) + 1]);
    std::reverse(shuffled.cols.begin() + b, shuffled.cols.begin() + e);
    std::reverse(shuffled.values.begin() + b, shuffled.values.begin() + e);
  }
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(sorted.rows, -1, 2);
  const Eigen::VectorXd x_ref = eigen_lu_solution(sorted, b);
  for (const CsrMatrix* a : std::vector<const CsrMatrix*>{&sorted, &shuffled}) {
    Eigen::VectorXd x;
    const auto st = make_linear_solver(s)->solve(*a, b, x);
    ASSERT_TRUE(st.converged);
    EXPECT_LT((x - x_ref).norm() / x_ref.norm(), 1e-10) << (a == &sorted ? "sorted rows" : "reversed rows");
  }
}

// gmres_amg on one rank keeps its prolongators while the pattern stays (MueLu
// reuse "RP": coarse operators and smoothers from the new values): the solves
// stay as accurate and about as short as a fresh hierarchy's; a grown pattern
// builds a fresh one (the same iteration count as a fresh solver).
TEST(AmgReuse, KeptProlongatorsSolveNewValuesAndANewPatternRebuilds) {
  const LinearSolverSettings s = scalar_amg(LinearSolverType::gmres_amg);
  const auto kept = make_linear_solver(s);
  Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(3375, -1, 2);
  int reused_differently = 0;
  // (skew, grown pattern, wx, wz): the anisotropy turns from x to z, so prolongators
  // smoothed with the first values differ clearly from fresh ones.
  struct Case { double skew; bool grown; double wx, wz; };
  for (const Case& c : std::vector<Case>{{0.0, false, 50, 1}, {0.9, false, 1, 50}, {-0.8, false, 1, 1}, {0.3, true, 50, 1}, {0.95, true, 1, 50}}) {
    const double skew = c.skew;
    const bool grown = c.grown;
    CsrMatrix a = grid_matrix(15, skew, grown, c.wx, c.wz);
    Eigen::VectorXd x_kept, x_fresh;
    const auto st_kept = kept->solve(a, b, x_kept);
    const auto st_fresh = make_linear_solver(s)->solve(a, b, x_fresh);
    ASSERT_TRUE(st_kept.converged && st_fresh.converged) << "skew " << skew;
    std::printf("skew %.2f%s: kept %d, fresh %d GMRES iterations\n", skew, grown ? " (grown)" : "", st_kept.iterations,
                st_fresh.iterations);
    EXPECT_LT((a.multiply(x_kept) - b).norm() / b.norm(), 1e-9) << "skew " << skew;
    EXPECT_LT((x_kept - x_fresh).norm() / x_fresh.norm(), 1e-8) << "skew " << skew;
    EXPECT_LE(st_kept.iterations, 1.5 * st_fresh.iterations) << "skew " << skew;  // even with the anisotropy turned
    EXPECT_GT(st_kept.amg_levels, 1) << "skew " << skew;
    const bool first_of_pattern = skew == 0.0 || skew == 0.3;
    if (first_of_pattern) EXPECT_EQ(st_kept.iterations, st_fresh.iterations) << "skew " << skew << ": a fresh hierarchy";
    else if (st_kept.iterations != st_fresh.iterations) ++reused_differently;
  }
  // The prolongators of the first values were kept (else the reuse was not exercised).
  EXPECT_GE(reused_differently, 1);
}

// gmres_amg_block keeps the whole matrix and block 1's AMG (its Tpetra matrix
// refilled in place) while the patterns stay: with the anisotropy turned from x
// to z between solves, a block matrix left with the old values would cost far
// more GMRES iterations than a fresh solver; the full matrix left with them
// would give a wrong solution.
TEST(AmgBlockReuse, RefilledBlocksSolveNewValuesAsAFreshSolver) {
  const LinearSolverSettings s = scalar_amg(LinearSolverType::gmres_amg_block);
  const auto kept = make_linear_solver(s);
  kept->set_amg_block(0, 3000);
  Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(3375, -1, 2);
  struct Case { double skew, wx, wz; };
  for (const Case& c : std::vector<Case>{{0.0, 50, 1}, {0.9, 1, 50}, {-0.8, 50, 1}, {0.3, 1, 1}}) {
    CsrMatrix a = grid_matrix(15, c.skew, false, c.wx, c.wz);
    const auto fresh = make_linear_solver(s);
    fresh->set_amg_block(0, 3000);
    Eigen::VectorXd x_kept, x_fresh;
    const auto st_kept = kept->solve(a, b, x_kept);
    const auto st_fresh = fresh->solve(a, b, x_fresh);
    ASSERT_TRUE(st_kept.converged && st_fresh.converged) << "skew " << c.skew;
    std::printf("block, skew %.2f: kept %d, fresh %d GMRES iterations\n", c.skew, st_kept.iterations, st_fresh.iterations);
    EXPECT_LT((a.multiply(x_kept) - b).norm() / b.norm(), 1e-9) << "skew " << c.skew;
    EXPECT_LT((x_kept - x_fresh).norm() / x_fresh.norm(), 1e-8) << "skew " << c.skew;
    EXPECT_LE(st_kept.iterations, 1.5 * st_fresh.iterations + 1) << "skew " << c.skew;
  }
}

// Contact pairs reserve entries that stay exactly zero until a point comes within
// reach. gmres_amg_block builds block 1's AMG without them and keeps that pattern
// (block_split.hpp, amg_matrix), so when they fill the hierarchy is reused, not
// rebuilt, and GMRES (whose operator has them) still solves to the tolerance in
// about as many iterations as a fresh solver.
TEST(AmgBlockReuse, ReservedEntriesThatFillKeepTheHierarchy) {
  const LinearSolverSettings s = scalar_amg(LinearSolverType::gmres_amg_block);
  const auto kept = make_linear_solver(s);
  kept->set_amg_block(0, 3000);
  Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(3375, -1, 2);
  // The long-range coupling inside block 1: (0, 2999) and (2999, 0), reserved as zeros first.
  auto with_coupling = [](double skew, double v) {
    CsrMatrix a = grid_matrix(15, skew);
    CsrMatrix c;
    c.rows = a.rows;
    c.row_ptr = {0};
    for (std::int64_t i = 0; i < a.rows; ++i) {
      std::vector<std::pair<std::int64_t, double>> row;
      for (auto k = a.row_ptr[i]; k < a.row_ptr[i + 1]; ++k) row.emplace_back(a.cols[k], a.values[k]);
      if (i == 0) row.emplace_back(2999, v);
      if (i == 2999) row.emplace_back(0, -0.5 * v);
      std::sort(row.begin(), row.end());
      for (const auto& [col, val] : row) c.cols.push_back(col), c.values.push_back(val);
      c.row_ptr.push_back(static_cast<std::int64_t>(c.cols.size()));
    }
    return c;
  };
  int built = 0;
  for (const auto& [skew, v] : std::vector<std::pair<double, double>>{{0.0, 0.0}, {0.2, 0.0}, {0.3, 2.0}, {-0.4, 3.0}}) {
    const CsrMatrix a = with_coupling(skew, v);
    const auto fresh = make_linear_solver(s);
    fresh->set_amg_block(0, 3000);
    Eigen::VectorXd x_kept, x_fresh;
    const auto st_kept = kept->solve(a, b, x_kept);
    const auto st_fresh = fresh->solve(a, b, x_fresh);
    ASSERT_TRUE(st_kept.converged && st_fresh.converged) << "skew " << skew;
    std::printf("block, reserved coupling %.1f: kept %d, fresh %d GMRES iterations%s\n", v, st_kept.iterations,
                st_fresh.iterations, st_kept.preconditioner_built ? " (built)" : "");
    EXPECT_TRUE(st_fresh.preconditioner_built);
    built += st_kept.preconditioner_built ? 1 : 0;
    EXPECT_LT((a.multiply(x_kept) - b).norm() / b.norm(), 1e-9) << "skew " << skew;
    EXPECT_LT((x_kept - x_fresh).norm() / x_fresh.norm(), 1e-8) << "skew " << skew;
    EXPECT_LE(st_kept.iterations, 1.5 * st_fresh.iterations + 2) << "skew " << skew;
  }
  EXPECT_EQ(built, 1) << "the hierarchy of the first solve serves the filled couplings too";
}

// Lagging (LinearSolverSettings::lag_preconditioner, lag_policy.hpp): the solve
// after a set-up keeps that preconditioner whatever the timings (nothing has been
// spent on it yet), and every lagged solve still reaches the tolerance on the
// current matrix. A matrix the lagged preconditioner no longer serves (the
// anisotropy turned 50:1) would take more GMRES iterations than max_iterations
// allows: that solve is repeated with a fresh set-up and converges.
TEST(LaggedPreconditioner, LaggedSolvesReachTheToleranceAndAFailedOneIsRepeatedFresh) {
  for (const LinearSolverType type : {LinearSolverType::gmres_amg, LinearSolverType::gmres_amg_block}) {
    const bool block = type == LinearSolverType::gmres_amg_block;
    LinearSolverSettings s = scalar_amg(type, true);
    s.max_iterations = 40;
    const auto solver = make_linear_solver(s);
    if (block) solver->set_amg_block(0, 3000);
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(3375, -1, 2);
    int lagged = 0;
    struct Case { double skew, wx, wz; };
    const std::vector<Case> cases{{0.0, 1, 1}, {0.02, 1, 1}, {0.04, 1, 1}, {0.06, 1, 1}, {0.1, 1, 50}};
    for (std::size_t k = 0; k < cases.size(); ++k) {
      const CsrMatrix a = grid_matrix(15, cases[k].skew, false, cases[k].wx, cases[k].wz);
      Eigen::VectorXd x;
      const auto st = solver->solve(a, b, x);
      std::printf("%s, matrix %zu: %d GMRES iterations%s%s\n", block ? "block" : "amg", k, st.iterations,
                  st.preconditioner_lagged ? " (lagged)" : "", st.preconditioner_built ? " (built)" : "");
      ASSERT_TRUE(st.converged) << "matrix " << k;
      EXPECT_LT((a.multiply(x) - b).norm() / b.norm(), 1e-9) << "matrix " << k;
      if (k == 0) {
        EXPECT_FALSE(st.preconditioner_lagged);
      } else if (k == 1) {
        EXPECT_TRUE(st.preconditioner_lagged) << "the solve after a set-up keeps it";
      }
      // gmres_amg_block's block 2 LU is lagged with block 1's AMG: factored only with a set-up.
      if (block) EXPECT_EQ(st.lu_factorizations, st.preconditioner_lagged ? 0 : 1) << "matrix " << k;
      lagged += st.preconditioner_lagged ? 1 : 0;
      if (k + 1 == cases.size()) {
        // A fresh solver needs far fewer than max_iterations here; the one set up for the
        // isotropic matrix would not reach the tolerance within them.
        const auto fresh = make_linear_solver(s);
        if (block) fresh->set_amg_block(0, 3000);
        Eigen::VectorXd y;
        const auto st_fresh = fresh->solve(a, b, y);
        ASSERT_TRUE(st_fresh.converged);
        EXPECT_FALSE(st.preconditioner_lagged) << "the turned matrix is solved with a fresh set-up";
        EXPECT_GT(st.iterations, st_fresh.iterations) << "its count includes the lagged attempt";
      }
    }
    EXPECT_GE(lagged, 1);
  }
}

// A factorization that fails (a singular matrix: a row of block 2 lost its
// stiffness) leaves no factors to lag: the next, regular matrix gets a fresh set-up
// (a new LU) and is solved, for gmres_amg_block (block 2's LU) and gmres_lu (the whole LU).
TEST(LaggedPreconditioner, AFailedFactorizationIsNotLagged) {
  for (const LinearSolverType type : {LinearSolverType::gmres_amg_block, LinearSolverType::gmres_lu}) {
    LinearSolverSettings s = scalar_amg(type, true);
    s.max_iterations = 40;
    const auto solver = make_linear_solver(s);
    solver->set_amg_block(0, 3000);
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(3375, -1, 2);
    Eigen::VectorXd x;
    ASSERT_TRUE(solver->solve(grid_matrix(15, 0.0), b, x).converged) << linear_solver_name(type);
    CsrMatrix singular = grid_matrix(15, 0.02);
    for (auto k = singular.row_ptr[3100]; k < singular.row_ptr[3101]; ++k) singular.values[static_cast<std::size_t>(k)] = 0.0;
    EXPECT_THROW(solver->solve(singular, b, x), std::runtime_error) << linear_solver_name(type);
    const CsrMatrix a = grid_matrix(15, 0.04);
    LinearSolveStats st;
    ASSERT_NO_THROW(st = solver->solve(a, b, x)) << linear_solver_name(type);
    // Refactored (block 1's AMG may be recomputed on its kept hierarchy rather than built).
    EXPECT_TRUE(st.converged && !st.preconditioner_lagged && st.lu_factorizations == 1) << linear_solver_name(type);
    EXPECT_LT((a.multiply(x) - b).norm() / b.norm(), 1e-9) << linear_solver_name(type);
  }
}

// gmres_lu: the first solve factors the whole matrix (one GMRES iteration to the
// tolerance); the next, of other values and a grown pattern, is solved with those
// factors (lagged: the solve after a set-up always keeps it) in a few iterations, to
// the tolerance on its own matrix, and so are the later ones while LagPolicy (on
// timings) keeps them; a matrix they cannot serve within max_iterations (the
// anisotropy turned 50:1) is solved with fresh factors. With every_solve each solve
// factors its own matrix.
TEST(LaggedPreconditioner, WholeMatrixLuServesLaterMatricesToTheTolerance) {
  LinearSolverSettings s;
  s.type = LinearSolverType::gmres_lu;
  s.tolerance = 1e-10;
  s.max_iterations = 12;
  const auto solver = make_linear_solver(s);
  EXPECT_NE(solver->describe().find("UMFPACK LU of the whole matrix"), std::string::npos) << solver->describe();
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(3375, -1, 2);
  struct Case { double skew; bool grown; double wz; };
  const std::vector<Case> cases{{0.0, false, 1}, {0.02, true, 1}, {0.04, true, 1}, {0.06, true, 1}, {0.1, true, 50}};
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const CsrMatrix a = grid_matrix(15, cases[k].skew, cases[k].grown, 1.0, cases[k].wz);
    Eigen::VectorXd x;
    const auto st = solver->solve(a, b, x);
    std::printf("gmres_lu, matrix %zu: %d GMRES iterations%s%s\n", k, st.iterations, st.preconditioner_lagged ? " (lagged)" : "",
                st.preconditioner_built ? " (built)" : "");
    ASSERT_TRUE(st.converged) << "matrix " << k;
    EXPECT_LT((a.multiply(x) - b).norm() / b.norm(), 1e-9) << "matrix " << k;
    EXPECT_NE(st.preconditioner_lagged, st.preconditioner_built) << "matrix " << k;
    EXPECT_EQ(st.lu_factorizations, st.preconditioner_lagged ? 0 : 1) << "matrix " << k;
    if (k == 0) {
      EXPECT_TRUE(st.preconditioner_built);
      EXPECT_LE(st.iterations, 2) << "GMRES on the matrix's own LU";
    } else if (k == 1) {
      EXPECT_TRUE(st.preconditioner_lagged) << "the first factors serve the grown pattern";
    }
    if (st.preconditioner_lagged) EXPECT_GE(st.iterations, 2) << "an earlier matrix's factors are not matrix " << k << "'s";
    if (k + 1 == cases.size()) EXPECT_TRUE(st.preconditioner_built) << "the turned matrix is solved with fresh factors";
  }
  s.lag_preconditioner = false;
  const auto every = make_linear_solver(s);
  for (double skew : {0.0, 0.02}) {
    Eigen::VectorXd x;
    const auto st = every->solve(grid_matrix(15, skew), b, x);
    EXPECT_TRUE(st.converged && st.preconditioner_built && !st.preconditioner_lagged) << "skew " << skew;
    EXPECT_LE(st.iterations, 2) << "skew " << skew;
  }
}
