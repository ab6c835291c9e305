// Sparse direct solver ("direct" on one rank): one UMFPACK factorization per
// solve (umfpack_factor.hpp; the symbolic analysis kept while the pattern stays).
#include <algorithm>
#include <chrono>

#include "solver/linalg/linear_solver.hpp"
#include "solver/linalg/umfpack_factor.hpp"

namespace stentsim::solver {
namespace {

class UmfpackSolver : public LinearSolver {
 public:
  LinearSolveStats solve(const CsrMatrix& a, const Eigen::VectorXd& b, Eigen::VectorXd& x) override {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    if (a.rows == 0) {
      x.resize(0);
      return LinearSolveStats{1, 0.0, true};
    }
    lu_.factor(a);
    const auto t1 = Clock::now();
    lu_.solve(b, x);
    const auto t2 = Clock::now();
    LinearSolveStats s;
    s.iterations = 1;
    s.lu_factorizations = 1;
    s.relative_residual = (a.multiply(x) - b).norm() / std::max(b.norm(), 1e-300);
    // A nearly singular matrix factors without UMFPACK's singular warning but
    // gives a useless solution: not "converged" then (Newton logs it).
    s.converged = x.allFinite() && s.relative_residual <= 1e-6;
    s.setup_seconds = std::chrono::duration<double>(t1 - t0).count();
    s.solve_seconds = std::chrono::duration<double>(t2 - t1).count();
    return s;
  }

  std::string describe() const override { return "UMFPACK sparse LU (direct)"; }

 private:
  UmfpackFactor lu_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_umfpack_solver() { return std::make_unique<UmfpackSolver>(); }

}  // namespace stentsim::solver
