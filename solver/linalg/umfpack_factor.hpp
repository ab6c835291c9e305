#pragma once
// One SuiteSparse UMFPACK factorization (Davis 2004, ACM TOMS 30(2)) of a
// CSR matrix, solved against many right-hand sides: the direct solver
// (umfpack_solver.cpp), the direct block of gmres_amg_block's preconditioner
// and gmres_lu's preconditioner (trilinos_solvers.cpp) share it.
//
// The symbolic analysis depends on the pattern only, so it is kept while the
// pattern stays the same (every Newton iteration of a solid scene) and only
// the numeric factorization is redone.
#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "solver/linalg/csr_matrix.hpp"

namespace stentsim::solver {

class UmfpackFactor {
 public:
  /// `refine`: UMFPACK's iterative refinement after each solve (its default, up
  /// to two steps, each a residual and a further solve). A preconditioner's
  /// block solve needs no refinement: GMRES corrects it, and refinement would
  /// triple the block's share of every Krylov iteration.
  explicit UmfpackFactor(bool refine = true);
  ~UmfpackFactor();
  UmfpackFactor(const UmfpackFactor&) = delete;
  UmfpackFactor& operator=(const UmfpackFactor&) = delete;

  /// Factorizes `a`. With refinement `a` is kept by reference and must
  /// outlive the solves; without, the solves read the factors only, so `a` may
  /// change or go (a preconditioner kept for later matrices). Throws
  /// std::runtime_error naming UMFPACK's reason when it cannot.
  void factor(const CsrMatrix& a);
  /// x = A⁻¹ b with the last factorization.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;
  /// Rows of the last successful factorization; -1 before one and after a failed one
  /// (whose earlier factors are gone).
  std::int64_t rows() const { return rows_; }

 private:
  void release();
  bool refine_ = true;
  std::int64_t rows_ = -1;
  const CsrMatrix* a_ = nullptr;  // for the refinement only
  double control_[20]{};      // UMFPACK_CONTROL
  mutable double info_[90]{};  // UMFPACK_INFO
  void* symbolic_ = nullptr;
  void* numeric_ = nullptr;
  std::vector<std::int64_t> row_ptr_, cols_;  // the pattern symbolic_ was built for
};

}  // namespace stentsim::solver
