#pragma once
// Dead loads on beam bodies, each a Term (solver/terms/term.hpp).
// - NodalLoadTerm: a dead force at position DOFs or a dead moment at rotation
//   DOFs. The moment is a fixed spatial vector; its work conjugate is the
//   spatial virtual rotation of the update convention (beam_term.hpp), so its
//   residual −λ(t)·M is configuration independent and its tangent is zero.
//   (A fixed spatial moment is not conservative for 3D rotations; the
//   equilibrium still depends only on the current load.)
// - BeamLineLoadTerm: a dead distributed force f per unit reference length,
//   R_k −= λ(t) ∫ B_k f ds over the centerline functions (positions and, for
//   Hermite elements, tangents).
#include "solver/beams/beam_term.hpp"
#include "solver/terms/term.hpp"

#include <Eigen/Core>

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace stentsim::solver::beams {

/// Load level as a function of pseudo-time (a load curve).
using LoadScale = std::function<double(double time)>;

class NodalLoadTerm : public Term {
 public:
  NodalLoadTerm(std::string name, std::array<GlobalDof, 3> dofs, Eigen::Vector3d value, LoadScale scale);
  std::string name() const override { return name_; }
  void assemble(const SystemState& state, Assembler& out) override;
  void set_value(const Eigen::Vector3d& v) { value_ = v; }

 private:
  std::string name_;
  std::array<GlobalDof, 3> dofs_;
  Eigen::Vector3d value_;
  LoadScale scale_;
};

class BeamLineLoadTerm : public Term {
 public:
  /// `elements` empty: every element of the body.
  BeamLineLoadTerm(std::string name, const BeamTerm& beam, Eigen::Vector3d force_per_length, LoadScale scale,
                   std::vector<std::size_t> elements = {});
  std::string name() const override { return name_; }
  void assemble(const SystemState& state, Assembler& out) override;
  /// The load per unit reference length at `time` and the elements it acts on
  /// (for the output's resultant recovery, beam_resultants.hpp).
  Eigen::Vector3d force_per_length(double time) const { return (scale_ ? scale_(time) : 1.0) * f_; }
  const std::vector<std::size_t>& elements() const { return elements_; }

 private:
  std::string name_;
  const BeamTerm& beam_;
  Eigen::Vector3d f_;
  LoadScale scale_;
  std::vector<std::size_t> elements_;
};

}  // namespace stentsim::solver::beams
