#pragma once
// Test driver for the beam terms. Solves go through the solver core
// (Model, Constraints, GlobalSystem, newton_step with Eigen LU, no line
// search); `assemble` returns the dense residual and tangent of the terms for
// the finite-difference and objectivity checks, which are not solves.
#include "solver/assembly/model.hpp"
#include "solver/linalg/linear_solver.hpp"
#include "solver/nonlinear/newton.hpp"
#include "solver/terms/term.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <memory>
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

/// Records which DOFs any term touches.
class TouchedDofs : public Assembler {
 public:
  explicit TouchedDofs(GlobalDof n) : touched(static_cast<std::size_t>(n), false) {}
  void add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>&,
           const Eigen::Ref<const Eigen::MatrixXd>&) override {
    for (GlobalDof d : dofs)
      if (d >= 0) touched[static_cast<std::size_t>(d)] = true;
  }
  std::vector<bool> touched;
};

/// A term the test owns, seen by the Model (which owns its terms).
class ForwardTerm : public Term {
 public:
  explicit ForwardTerm(Term* t) : t_(t) {}
  std::string name() const override { return t_->name(); }
  void assemble(const SystemState& s, Assembler& out) override { t_->assemble(s, out); }
  void trial(const Eigen::VectorXd& du) override { t_->trial(du); }
  void accept() override { t_->accept(); }
  void commit() override { t_->commit(); }
  void rollback() override { t_->rollback(); }

 private:
  Term* t_;
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
  /// One load step ending at `time` by the solver core's Newton until |du| <= tol;
  /// commits and returns the iterations. Throws if not converged.
  int solve(double time, double tol, int max_iterations = 40) {
    Model model;
    model.dofs.allocate("test", u.size());
    model.size_constraints();
    for (Term* t : terms) model.add_term<ForwardTerm>(t);
    for (GlobalDof d : fixed) model.constraints.fix(d, [v = u[d]](double) { return v; });
    // Tests remove DOFs from a term by setting them to −1 after numbering; the
    // numbers no term touches are held where they are.
    TouchedDofs touched(u.size());
    SystemState s{u, time, 0.0};
    for (Term* t : terms) t->assemble(s, touched);
    for (GlobalDof d = 0; d < u.size(); ++d)
      if (!touched.touched[static_cast<std::size_t>(d)]) model.constraints.fix(d, [v = u[d]](double) { return v; });
    GlobalSystem system(model.constraints);
    LinearSolverSettings ls;
    ls.type = LinearSolverType::eigen_lu;
    auto linear = make_linear_solver(ls);
    NewtonSettings ns;
    ns.max_iterations = max_iterations;
    ns.residual_tolerance = 1e300;  // the criterion here is the increment alone
    ns.increment_tolerance = 0.0;
    ns.increment_absolute = tol;
    ns.line_search_steps = 0;
    const NewtonResult r = newton_step(model, system, *linear, u, time, 0.0, ns);
    if (!r.converged) throw std::runtime_error("Newton (solver core): " + r.failure + " at time " + std::to_string(time));
    model.commit();
    return r.iterations;
  }
};

}  // namespace stentsim::solver::beams::testing
