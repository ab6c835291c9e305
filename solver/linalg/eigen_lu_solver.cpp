#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <chrono>
#include <stdexcept>

#include "solver/linalg/linear_solver.hpp"

namespace stentsim::solver {
namespace {

class EigenLuSolver : public LinearSolver {
 public:
  LinearSolveStats solve(const CsrMatrix& a, const Eigen::VectorXd& b, Eigen::VectorXd& x) override {
    const auto t0 = std::chrono::steady_clock::now();
    Eigen::SparseMatrix<double, Eigen::RowMajor, std::int64_t> m(a.rows, a.rows);
    std::vector<Eigen::Triplet<double, std::int64_t>> trip;
    trip.reserve(a.values.size());
    for (std::int64_t i = 0; i < a.rows; ++i)
      for (auto k = a.row_ptr[static_cast<std::size_t>(i)]; k < a.row_ptr[static_cast<std::size_t>(i) + 1]; ++k)
        trip.emplace_back(i, a.cols[static_cast<std::size_t>(k)], a.values[static_cast<std::size_t>(k)]);
    m.setFromTriplets(trip.begin(), trip.end());
    Eigen::SparseMatrix<double> mc = m;
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.compute(mc);
    if (lu.info() != Eigen::Success) throw std::runtime_error("SparseLU: factorization failed (singular matrix?)");
    const auto t1 = std::chrono::steady_clock::now();
    x = lu.solve(b);
    const auto t2 = std::chrono::steady_clock::now();
    LinearSolveStats s;
    s.iterations = 1;
    s.relative_residual = (mc * x - b).norm() / std::max(b.norm(), 1e-300);
    s.converged = x.allFinite();
    s.setup_seconds = std::chrono::duration<double>(t1 - t0).count();
    s.solve_seconds = std::chrono::duration<double>(t2 - t1).count();
    return s;
  }
  std::string describe() const override { return "Eigen SparseLU (direct)"; }
};

}  // namespace

std::unique_ptr<LinearSolver> make_eigen_lu_solver() { return std::make_unique<EigenLuSolver>(); }

std::unique_ptr<LinearSolver> make_linear_solver(const LinearSolverSettings& settings) {
  if (settings.type == LinearSolverType::eigen_lu) return make_eigen_lu_solver();
  return make_trilinos_solver(settings);
}

}  // namespace stentsim::solver
