#pragma once
// A body of geometrically exact Simo–Reissner beam elements as one Term
// (solver/terms/term.hpp): it adds residual and tangent over its DOFs and owns
// the nodal triads, which it updates multiplicatively.
//
// Rotation increments: spatial (left) convention, Λ <- exp(S(Δθ)) Λ, stored as
// quaternions q <- qexp(Δθ) ⊗ q (Simo & Vu-Quoc 1986, eq. 2.6; term.hpp). The
// residual at a rotation DOF is the work conjugate of a spatial virtual
// rotation δθ (δΛ = S(δθ) Λ), and the tangent is its derivative along this
// update (beam_kernel.hpp).
//
// Additive DOFs in the global vector u: positions r = X + u (end nodes),
// Hermite tangents t = T₀ + u (end nodes, T₀ = d1 of the reference triad).
#include "solver/beams/beam_kernel.hpp"
#include "solver/beams/element_reference.hpp"
#include "solver/beams/section.hpp"
#include "solver/terms/term.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <string>
#include <vector>

namespace stentsim::solver::beams {

struct BeamNode {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond triad = Eigen::Quaterniond::Identity();  // reference Λ₀ = [d1 d2 d3], d1 = tangent
};

/// Element connectivity: end nodes a, b; Hermite elements also a middle node
/// (rotation only, at ξ = 0).
struct BeamElement {
  int a = -1, b = -1, mid = -1;
};

struct BeamBodyDefinition {
  BeamInterpolation interpolation = BeamInterpolation::hermite3;
  std::vector<BeamNode> nodes;
  std::vector<BeamElement> elements;
  BeamSection section;
  int gauss_points = 0;  // 0: default of the interpolation
};

/// Global DOFs of one node; −1 = fixed (homogeneous Dirichlet) or absent
/// (middle nodes have only `rot`; Lagrange nodes have no `tan`).
struct BeamNodeDofs {
  std::array<GlobalDof, 3> pos{-1, -1, -1}, rot{-1, -1, -1}, tan{-1, -1, -1};
};

/// Does node `n` carry positions and tangents (an end node) or only a rotation?
std::vector<bool> beam_end_nodes(const BeamBodyDefinition& body);
/// Number of nodal DOFs before constraints: 9 per Hermite end node, 3 per
/// middle node, 6 per Lagrange node (DESIGN.md §2).
long long beam_nodal_dof_count(const BeamBodyDefinition& body);
/// Consecutive DOF numbers starting at `first` (test helper and a default for
/// the solver core's DOF map); returns the next free number in `next`.
std::vector<BeamNodeDofs> number_beam_dofs(const BeamBodyDefinition& body, GlobalDof first, GlobalDof* next);

class BeamTerm : public Term {
 public:
  BeamTerm(std::string name, BeamBodyDefinition body, std::vector<BeamNodeDofs> dofs);

  std::string name() const override { return name_; }
  void assemble(const SystemState& state, Assembler& out) override;
  void trial(const Eigen::VectorXd& du) override;
  void accept() override;
  /// Plastic sections: throws std::logic_error unless the last assemble()
  /// was at the accepted state (the converged one), whose trial history it keeps.
  void commit() override;
  void rollback() override;
  /// Restart: the committed nodal triads (quaternions w, x, y, z per node) under
  /// "<prefix>triads"; plastic sections add "<prefix>plastic" (Ω_pl and Ω̄_pl
  /// per Gauss point), "<prefix>plastic_work" and "<prefix>yielded" (1 per Gauss
  /// point that flowed in the last committed step; optional on load).
  bool has_history() const override { return true; }
  void save_history(HistoryArchive& out, const std::string& prefix) const override;
  void load_history(const HistoryArchive& in, const std::string& prefix) override;

  const BeamBodyDefinition& body() const { return body_; }
  const std::vector<BeamNodeDofs>& dofs() const { return dofs_; }
  const ElementReference& reference(std::size_t e) const { return refs_[e]; }
  /// Global DOFs of element e in the kernel's split order
  /// [x_0 … x_{NC−1}, θ_0 … θ_{NT−1}] (see beam_kernel.hpp).
  std::vector<GlobalDof> element_dofs(std::size_t e) const;

  /// Current (trial) triad of a node.
  Eigen::Quaterniond rotation(int node) const { return trial_[node]; }
  /// Prescribes a node's triad (non-homogeneous rotation Dirichlet, or a test
  /// state): sets the trial and accepted triads; commit() makes it history.
  void set_rotation(int node, const Eigen::Quaterniond& q);
  Eigen::Vector3d position(const Eigen::VectorXd& u, int node) const;
  Eigen::Vector3d tangent(const Eigen::VectorXd& u, int node) const;

  /// Section states at the quadrature points of element e: the return at u
  /// from the committed history (at the committed u: the committed moment;
  /// `yielding` there is Φ_trial > 0 of that return, see yielded_last_step()).
  std::vector<SectionState> section_states(const Eigen::VectorXd& u, std::size_t e) const;
  /// Section state at any ξ ∈ [−1, 1] of element e (output sampling):
  /// position and triad at ξ; strains, forces, moments (and, for
  /// elasto-plastic sections, the committed plastic history and `yielding`)
  /// those of the nearest Gauss point, piecewise constant along the element,
  /// because resultants are only reliable there and the plastic state exists
  /// only there; `yielding` = that point flowed in the last committed step.
  /// The VTU output writes position, triad and the plastic state from here,
  /// and forces (elastic sections: moments too) recovered by equilibrium
  /// (beam_resultants.hpp), which are smooth and far more accurate than F, M here.
  SectionState sample(const Eigen::VectorXd& u, std::size_t e, double xi) const;
  /// The element's internal force vector at u (gradient of its stored energy,
  /// no loads; for plastic sections the return from the committed history),
  /// the input of the equilibrium-based resultant recovery (beam_resultants.hpp).
  struct InternalForce {
    std::array<Eigen::Vector3d, 4> x{};      // current centerline vectors (Hermite r_a, t_a, r_b, t_b; Lagrange r_a, r_b)
    std::array<Eigen::Vector3d, 4> force{};  // their conjugate forces ∫ B'_k n ds
    std::array<Eigen::Vector3d, 3> moment{};  // conjugates of the spatial virtual rotations of the nodal triads (a, b[, mid])
  };
  InternalForce internal_force(const Eigen::VectorXd& u, std::size_t e) const;
  /// Stored (elastic) energy of the body at u and the current triads; for
  /// plastic sections from the return of the committed history.
  double energy(const Eigen::VectorXd& u) const;

  /// Elasto-plastic sections: Gauss-point history of element e, point g
  /// (committed, and the trial state of the last assemble()).
  const PlasticBendingHistory& committed_plastic(std::size_t e, int g) const { return hist_committed_[hist_offset_[e] + g]; }
  const PlasticBendingHistory& trial_plastic(std::size_t e, int g) const { return hist_trial_[hist_offset_[e] + g]; }
  /// Did Gauss point g of element e flow in the last committed step? (Set by
  /// commit(), kept by rollback(), saved in checkpoints.)
  bool yielded_last_step(std::size_t e, int g) const { return yielded_committed_[hist_offset_[e] + g] != 0; }
  /// Plastic work ∫∫ M_b·dΩ_pl ds summed over committed steps (= ∫ M_y dΩ̄,
  /// exact for linear hardening) [N·mm].
  double plastic_work() const { return plastic_work_committed_; }

 private:
  void gather(const Eigen::VectorXd& u, std::size_t e, std::array<Eigen::Vector3d, 4>& x,
              std::array<Eigen::Quaterniond, 3>& q) const;

  std::string name_;
  BeamBodyDefinition body_;
  std::vector<BeamNodeDofs> dofs_;
  std::vector<ElementReference> refs_;
  std::vector<Eigen::Quaterniond> committed_, accepted_, trial_;
  std::vector<std::size_t> hist_offset_;  // first Gauss point of element e
  std::vector<PlasticBendingHistory> hist_committed_, hist_trial_;
  std::vector<char> yielded_committed_;  // per Gauss point: flowed in the last committed step
  std::vector<double> work_trial_;  // plastic work increment of element e in the last assemble
  // Element systems a chunk of the threaded loop holds until its turn to scatter, per slot.
  std::vector<std::vector<ElementSystem<4, 3>>> hermite_slots_;
  std::vector<std::vector<ElementSystem<2, 2>>> linear_slots_;
  std::vector<std::vector<std::vector<GlobalDof>>> slot_dofs_;  // and their elements' DOFs
  double plastic_work_committed_ = 0.0;
  // Which state the trial history belongs to: trial()/set_rotation() start a
  // new state, accept() marks it accepted, assemble() marks the history as
  // evaluated at it. commit() of a plastic body requires the accepted state
  // to be the assembled one (see commit()).
  long long state_serial_ = 0, accepted_serial_ = 0, assembled_serial_ = 0;
};

}  // namespace stentsim::solver::beams
