#pragma once
// Dirichlet constraints on single DOFs, optionally in a local nodal frame:
// a node triple (d, d+1, d+2) may carry an orthonormal frame Q (columns =
// local axes in global coordinates; u = Q u_local), so that "moves only
// radially" fixes the two non-radial local components. The global system is
// assembled in these local coordinates (K' = T^T K T, R' = T^T R); the
// Newton increment is rotated back.
#include <Eigen/Core>

#include <functional>
#include <unordered_map>
#include <vector>

#include "solver/fem/tensor.hpp"
#include "solver/terms/term.hpp"

namespace stentsim::solver {

class Constraints {
 public:
  explicit Constraints(GlobalDof n = 0) { resize(n); }
  void resize(GlobalDof n);
  GlobalDof size() const { return static_cast<GlobalDof>(fixed_.size()); }

  /// Local frame for the node whose DOFs are first..first+2. Re-setting keeps the last.
  void set_frame(GlobalDof first, const Mat3& q);
  /// Fix DOF `dof` (a local component if its node has a frame) to value(t).
  void fix(GlobalDof dof, std::function<double(double)> value);

  bool fixed(GlobalDof dof) const { return fixed_[static_cast<std::size_t>(dof)] != 0; }
  /// The frame of the node triple starting at `first`, or nullptr.
  const Mat3* frame(GlobalDof first) const;
  bool has_frames() const { return !frames_.empty(); }
  bool frame_start(GlobalDof dof) const { return frame_start_[static_cast<std::size_t>(dof)] != 0; }
  std::size_t num_fixed() const;

  /// Prescribed increments at time t from the state u (local coordinates;
  /// zero at free DOFs).
  Eigen::VectorXd increments(const Eigen::VectorXd& u, double t) const;
  /// Global -> local (T^T v) and local -> global (T v) for vectors.
  void to_local(Eigen::VectorXd& v) const;
  void to_global(Eigen::VectorXd& v) const;

 private:
  std::vector<char> fixed_, frame_start_;
  std::unordered_map<GlobalDof, std::function<double(double)>> values_;
  std::unordered_map<GlobalDof, Mat3> frames_;
};

}  // namespace stentsim::solver
