#pragma once
// Finite-difference helpers shared by the solver tests.
#include <Eigen/Core>

#include <functional>

namespace stentsim::solver::test {

/// Central-difference Jacobian of f at x (columns = d f / d x_j).
inline Eigen::MatrixXd fd_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                   const Eigen::VectorXd& x, double h) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd j(f0.size(), x.size());
  for (Eigen::Index c = 0; c < x.size(); ++c) {
    Eigen::VectorXd xp = x, xm = x;
    xp(c) += h;
    xm(c) -= h;
    j.col(c) = (f(xp) - f(xm)) / (2 * h);
  }
  return j;
}

/// ||a - b|| / ||b|| (Frobenius).
inline double rel_error(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / b.norm(); }

}  // namespace stentsim::solver::test
