// GlobalSystem's scatter (global_system.hpp) against a dense reference built
// entry by entry: element blocks with repeated DOFs (a joint's shared numbers),
// unused slots (-1), fixed DOFs (their columns go to the right-hand side with
// the prescribed values), blocks whose entries are partly outside the current
// pattern (the pattern grows in finish()) and partly inside it, and the same
// blocks again into the grown pattern; and overlapping blocks outside the
// pattern in numbers that make the pending entries merge before finish().
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include <Eigen/Dense>

#include "solver/assembly/constraints.hpp"
#include "solver/assembly/global_system.hpp"

namespace stentsim::solver {
namespace {

struct Block {
  std::vector<GlobalDof> dofs;
  Eigen::VectorXd r;
  Eigen::MatrixXd k;
};

Eigen::MatrixXd dense(const CsrMatrix& a) {
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(a.rows, a.rows);
  for (std::int64_t i = 0; i < a.rows; ++i)
    for (auto e = a.row_ptr[static_cast<std::size_t>(i)]; e < a.row_ptr[static_cast<std::size_t>(i) + 1]; ++e)
      d(i, a.cols[static_cast<std::size_t>(e)]) += a.values[static_cast<std::size_t>(e)];
  return d;
}

TEST(GlobalSystem, ScatterMatchesADenseReferenceWithRepeatedFixedAndNewEntries) {
  constexpr GlobalDof n = 40;
  Constraints constraints(n);
  const std::vector<GlobalDof> fixed = {3, 17, 29};
  for (GlobalDof d : fixed) constraints.fix(d, [](double) { return 0.0; });
  Eigen::VectorXd prescribed = Eigen::VectorXd::Zero(n);
  prescribed(3) = 0.5, prescribed(17) = -0.25, prescribed(29) = 1.5;

  std::mt19937 rng(7);
  std::uniform_int_distribution<GlobalDof> pick(-1, n - 1);
  std::uniform_real_distribution<double> val(-1.0, 1.0);
  std::vector<Block> blocks;
  for (int b = 0; b < 60; ++b) {
    Block blk;
    const int m = 3 + b % 9;
    for (int i = 0; i < m; ++i) blk.dofs.push_back(pick(rng));
    if (m > 4) blk.dofs[4] = blk.dofs[1];  // a repeated DOF in one block
    blk.r = Eigen::VectorXd::NullaryExpr(m, [&] { return val(rng); });
    blk.k = Eigen::MatrixXd::NullaryExpr(m, m, [&] { return val(rng); });
    blocks.push_back(blk);
  }
  // The reference: free rows only; a fixed column moves k·prescribed to the right-hand side.
  Eigen::MatrixXd k_ref = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd r_ref = Eigen::VectorXd::Zero(n), corr = Eigen::VectorXd::Zero(n);
  for (const Block& blk : blocks)
    for (std::size_t i = 0; i < blk.dofs.size(); ++i) {
      const GlobalDof gi = blk.dofs[i];
      if (gi < 0) continue;
      r_ref(gi) += blk.r(static_cast<Eigen::Index>(i));
      if (constraints.fixed(gi)) continue;
      for (std::size_t j = 0; j < blk.dofs.size(); ++j) {
        const GlobalDof gj = blk.dofs[j];
        if (gj < 0) continue;
        const double v = blk.k(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
        if (constraints.fixed(gj)) corr(gi) += v * prescribed(gj);
        else k_ref(gi, gj) += v;
      }
    }
  for (GlobalDof d : fixed) k_ref(d, d) = 1.0;

  GlobalSystem system(constraints);
  // First pass: the first half of the blocks makes a pattern the second half partly misses.
  system.begin(prescribed, true);
  for (std::size_t b = 0; b < blocks.size() / 2; ++b) system.add(blocks[b].dofs, blocks[b].r, blocks[b].k);
  system.finish();
  auto version = system.matrix().pattern_version;
  for (int pass = 0; pass < 2; ++pass) {  // then all blocks, twice: into a growing, then a settled pattern
    system.begin(prescribed, true);
    for (const Block& blk : blocks) system.add(blk.dofs, blk.r, blk.k);
    system.finish();
    EXPECT_LT((dense(system.matrix()) - k_ref).norm(), 1e-12 * k_ref.norm()) << "pass " << pass;
    Eigen::VectorXd b_ref(n);
    for (GlobalDof d = 0; d < n; ++d) b_ref(d) = constraints.fixed(d) ? prescribed(d) : -(r_ref(d) + corr(d));
    EXPECT_LT((system.rhs() - b_ref).norm(), 1e-12 * b_ref.norm()) << "pass " << pass;
    if (pass == 0) EXPECT_GT(system.matrix().pattern_version, version);  // the second half added entries
    else EXPECT_EQ(system.matrix().pattern_version, version);            // and then the pattern stays
    version = system.matrix().pattern_version;
  }
}

TEST(GlobalSystem, OverlappingNewBlocksMergeTheirPendingEntries) {
  // 400 overlapping 120 x 120 blocks on 600 DOFs: 5.8 M adds outside an empty pattern,
  // past the 4 M at which pending entries are merged, on 360,000 distinct entries.
  constexpr GlobalDof n = 600;
  constexpr int m = 120, blocks = 400;
  Constraints constraints(n);
  GlobalSystem system(constraints);
  Eigen::MatrixXd k_ref = Eigen::MatrixXd::Zero(n, n);
  std::vector<Block> all;
  for (int b = 0; b < blocks; ++b) {
    Block blk;
    for (int i = 0; i < m; ++i) blk.dofs.push_back((b + 3 * i) % n);
    blk.r = Eigen::VectorXd::Constant(m, 1.0);
    blk.k = Eigen::MatrixXd::NullaryExpr(m, m, [b](Eigen::Index i, Eigen::Index j) { return 1.0 + 1e-3 * b + 1e-6 * (i - j); });
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) k_ref(blk.dofs[static_cast<std::size_t>(i)], blk.dofs[static_cast<std::size_t>(j)]) += blk.k(i, j);
    all.push_back(std::move(blk));
  }
  system.begin(Eigen::VectorXd::Zero(n), true);
  for (const Block& blk : all) system.add(blk.dofs, blk.r, blk.k);
  system.finish();
  EXPECT_LT((dense(system.matrix()) - k_ref).norm(), 1e-12 * k_ref.norm());
  EXPECT_EQ(system.matrix().nonzeros(), (k_ref.array() != 0.0).count());
}

}  // namespace
}  // namespace stentsim::solver
