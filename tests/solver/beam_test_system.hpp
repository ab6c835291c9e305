#pragma once
// TEST-ONLY dense assembly and Newton loop that drive the beam terms until the
// solver core's global assembly (solver/assembly, solver/nonlinear) takes
// them. To be replaced by the real one, not kept beside it.
#include "solver/terms/term.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace stentsim::solver::beams::testing {

class DenseAssembler : public Assembler {
 public:
  explicit DenseAssembler(GlobalDof n) : K(Eigen::MatrixXd::Zero(n, n)), R(Eigen::VectorXd::Zero(n)) {}
  void add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& r,
           const Eigen::Ref<const Eigen::MatrixXd>& k) override {
    for (std::size_t i = 0; i < dofs.size(); ++i) {
      if (dofs[i] < 0) continue;
      R[dofs[i]] += r[i];
      for (std::size_t j = 0; j < dofs.size(); ++j)
        if (dofs[j] >= 0) K(dofs[i], dofs[j]) += k(i, j);
    }
  }
  Eigen::MatrixXd K;
  Eigen::VectorXd R;
};

struct TestSystem {
  std::vector<Term*> terms;
  Eigen::VectorXd u;
  /// DOFs held at their current value in u (non-homogeneous Dirichlet).
  std::vector<GlobalDof> fixed;
  explicit TestSystem(GlobalDof n) : u(Eigen::VectorXd::Zero(n)) {}

  DenseAssembler assemble(double time) const {
    DenseAssembler a(u.size());
    SystemState s{u, time, 0.0};
    for (Term* t : terms) t->assemble(s, a);
    return a;
  }
  /// Applies an increment: additive part to u, multiplicative part through the terms.
  void apply(const Eigen::VectorXd& du) {
    u += du;
    for (Term* t : terms) t->trial(du);
    for (Term* t : terms) t->accept();
  }
  /// Newton to |du| <= tol; returns the iterations. Throws if not converged.
  int solve(double time, double tol, int max_iterations = 40) {
    for (int it = 1; it <= max_iterations; ++it) {
      DenseAssembler a = assemble(time);
      for (GlobalDof d : fixed) {
        a.K.row(d).setZero();
        a.K.col(d).setZero();
        a.K(d, d) = 1.0;
        a.R[d] = 0.0;
      }
      const Eigen::VectorXd du = a.K.partialPivLu().solve(-a.R);
      if (!du.allFinite()) throw std::runtime_error("test Newton: non-finite increment");
      apply(du);
      if (du.norm() <= tol) {
        for (Term* t : terms) t->commit();
        return it;
      }
    }
    throw std::runtime_error("test Newton: no convergence at time " + std::to_string(time));
  }
};

}  // namespace stentsim::solver::beams::testing
