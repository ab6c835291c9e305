#pragma once
// A discrete model: the DOF map, the terms that add to residual and tangent,
// and the constraints. Scenes build one; the nonlinear solver drives it.
#include <memory>
#include <vector>

#include "solver/assembly/constraints.hpp"
#include "solver/assembly/dof_map.hpp"
#include "solver/assembly/global_system.hpp"
#include "solver/terms/term.hpp"

namespace stentsim::solver {

class Model {
 public:
  DofMap dofs;
  std::vector<std::unique_ptr<Term>> terms;
  Constraints constraints;
  int rank = 0, ranks = 1;

  template <class T, class... Args>
  T& add_term(Args&&... args) {
    auto t = std::make_unique<T>(std::forward<Args>(args)...);
    T& ref = *t;
    terms.push_back(std::move(t));
    return ref;
  }
  /// Call after all DOFs are allocated and before constraints are set.
  void size_constraints() { constraints.resize(dofs.size()); }

  /// Assembles every term at (u, time, dt) into `system`.
  void assemble(const Eigen::VectorXd& u, double time, double dt, const Eigen::VectorXd& prescribed,
                GlobalSystem& system, bool with_tangent = true);

  /// Every term's begin_step at (u, time, dt): before each attempt of a load step. A term that
  /// cannot prepare the step (ElementFailure) on one rank fails it on every rank.
  void begin_step(const Eigen::VectorXd& u, double time, double dt);
  void trial(const Eigen::VectorXd& du) { for (auto& t : terms) t->trial(du); }
  void accept() { for (auto& t : terms) t->accept(); }
  /// Active-set changes of the last accept() over all terms and ranks.
  int accepted_changes() const;
  /// The first term's reason not to accept the converged state (u, time, dt), or empty.
  std::string rejects(const Eigen::VectorXd& u, double time, double dt) const;
  void commit() { for (auto& t : terms) t->commit(); }
  void rollback() { for (auto& t : terms) t->rollback(); }
  /// Restart: every term's committed history under "term/<index>:<name>/".
  void save_history(HistoryArchive& out) const;
  void load_history(const HistoryArchive& in);

  /// Rigid-body modes of the 3-DOF-per-node part (n x 6) from reference positions, for AMG.
  Eigen::MatrixXd rigid_body_modes(const std::vector<std::pair<GlobalDof, Vec3>>& nodes) const;
};

}  // namespace stentsim::solver
