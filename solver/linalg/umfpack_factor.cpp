// UMFPACK factorization (umfpack_factor.hpp). Why not Amesos2 KLU2: KLU orders for circuit matrices (BTF + COLAMD); on a
// 3D finite-element matrix its fill explodes (Case 1 artery, 27,216 DOFs:
// 60 s per factorization). UMFPACK detects the symmetric pattern and orders
// A + A' with AMD (or METIS), which is what FE matrices need.
//
// The CSR arrays are handed to UMFPACK as the compressed columns of A', which
// it factorizes; solving with UMFPACK_At then gives A x = b.
#include <umfpack.h>

#include <chrono>
#include <stdexcept>
#include <string>

#include "common/log.hpp"
#include "solver/linalg/umfpack_factor.hpp"

namespace stentsim::solver {
namespace {

static_assert(sizeof(SuiteSparse_long) == sizeof(std::int64_t), "UMFPACK's long index must be the CSR index type");

std::string umfpack_status_text(SuiteSparse_long status) {
  switch (status) {
    case UMFPACK_WARNING_singular_matrix: return "the matrix is singular (a rigid-body motion not held, or an element with no stiffness?)";
    case UMFPACK_ERROR_out_of_memory: return "out of memory";
    case UMFPACK_ERROR_invalid_matrix: return "invalid matrix (unsorted or duplicate column indices)";
    case UMFPACK_ERROR_different_pattern: return "the pattern changed since the symbolic analysis";
    default: return "status " + std::to_string(status);
  }
}

const char* strategy_name(double s) {
  return s == UMFPACK_STRATEGY_SYMMETRIC ? "symmetric" : s == UMFPACK_STRATEGY_UNSYMMETRIC ? "unsymmetric" : "other";
}
const char* ordering_name(double o) {
  if (o == UMFPACK_ORDERING_AMD) return "AMD";
  if (o == UMFPACK_ORDERING_METIS) return "METIS";
  if (o == UMFPACK_ORDERING_CHOLMOD) return "CHOLMOD";
  if (o == UMFPACK_ORDERING_NONE) return "none";
  return "other";
}

}  // namespace

static_assert(UMFPACK_CONTROL == 20 && UMFPACK_INFO == 90, "umfpack_factor.hpp sizes its arrays by UMFPACK's");

UmfpackFactor::UmfpackFactor(bool refine) : refine_(refine) {
  umfpack_dl_defaults(control_);
  if (!refine) control_[UMFPACK_IRSTEP] = 0;
  // Orders A + A' by AMD and METIS and keeps the one with less fill: the
  // analysis is paid once per pattern.
  control_[UMFPACK_ORDERING] = UMFPACK_ORDERING_BEST;
}

UmfpackFactor::~UmfpackFactor() { release(); }

void UmfpackFactor::release() {
  if (numeric_) umfpack_dl_free_numeric(&numeric_);
  if (symbolic_) umfpack_dl_free_symbolic(&symbolic_);
  numeric_ = symbolic_ = nullptr;
}

void UmfpackFactor::factor(const CsrMatrix& a) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  rows_ = -1;  // until this factorization succeeds
  a_ = refine_ ? &a : nullptr;
  if (a.rows == 0) {
    rows_ = 0;
    return;
  }
  const SuiteSparse_long n = a.rows;
  const auto* ap = reinterpret_cast<const SuiteSparse_long*>(a.row_ptr.data());
  const auto* ai = reinterpret_cast<const SuiteSparse_long*>(a.cols.data());
  if (!symbolic_ || a.row_ptr != row_ptr_ || a.cols != cols_) {
    release();
    const SuiteSparse_long st = umfpack_dl_symbolic(n, n, ap, ai, a.values.data(), &symbolic_, control_, info_);
    if (st != UMFPACK_OK) {
      symbolic_ = nullptr;
      throw std::runtime_error("UMFPACK symbolic analysis failed: " + umfpack_status_text(st));
    }
    row_ptr_ = a.row_ptr;
    cols_ = a.cols;
    log::debug("UMFPACK analysis: n = {}, nnz(A) = {}, estimated nnz(L + U) = {:.0f}, {:.0f} MB ({} strategy, {} ordering), "
               "{:.2f} s", n, a.nonzeros(), info_[UMFPACK_LNZ_ESTIMATE] + info_[UMFPACK_UNZ_ESTIMATE],
               info_[UMFPACK_NUMERIC_SIZE_ESTIMATE] * info_[UMFPACK_SIZE_OF_UNIT] / 1e6,
               strategy_name(info_[UMFPACK_STRATEGY_USED]), ordering_name(info_[UMFPACK_ORDERING_USED]),
               std::chrono::duration<double>(Clock::now() - t0).count());
  }
  if (numeric_) umfpack_dl_free_numeric(&numeric_);
  const SuiteSparse_long st = umfpack_dl_numeric(ap, ai, a.values.data(), symbolic_, &numeric_, control_, info_);
  if (st != UMFPACK_OK) {
    if (numeric_) umfpack_dl_free_numeric(&numeric_);
    throw std::runtime_error("UMFPACK factorization failed: " + umfpack_status_text(st));
  }
  rows_ = a.rows;
  log::debug("UMFPACK factorization: nnz(L + U) = {:.0f}, {:.0f} MB, {:.3g} Gflop, {:.3f} s", info_[UMFPACK_LNZ] + info_[UMFPACK_UNZ],
             info_[UMFPACK_NUMERIC_SIZE] * info_[UMFPACK_SIZE_OF_UNIT] / 1e6, info_[UMFPACK_FLOPS] / 1e9,
             std::chrono::duration<double>(Clock::now() - t0).count());
}

void UmfpackFactor::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  if (rows_ < 0) throw std::logic_error("UmfpackFactor::solve: no factorization (none made, or the last one failed)");
  x.resize(b.size());
  if (rows_ == 0) return;
  // Without refinement UMFPACK does not read A (umfpack_solve.h: the arrays may then be NULL).
  const auto* ap = a_ ? reinterpret_cast<const SuiteSparse_long*>(a_->row_ptr.data()) : nullptr;
  const auto* ai = a_ ? reinterpret_cast<const SuiteSparse_long*>(a_->cols.data()) : nullptr;
  const double* ax = a_ ? a_->values.data() : nullptr;
  const SuiteSparse_long ss = umfpack_dl_solve(UMFPACK_At, ap, ai, ax, x.data(), b.data(), numeric_, control_, info_);
  if (ss != UMFPACK_OK) throw std::runtime_error("UMFPACK solve failed: " + umfpack_status_text(ss));
}

}  // namespace stentsim::solver
