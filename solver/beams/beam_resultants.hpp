#pragma once
// Section resultants along a beam element recovered by equilibrium (issue 8,
// output). The displacement element's constitutive force F = C_F Γ is poorly
// conditioned for a stiff section (EA = 1e7 on the 45° bend: Γ ~ 1e-5, and
// |F| at the Gauss points is up to 27 % off the exact 600), so the output does
// not take it from the strains. Instead, for the static rod (Simo 1985, eq.
// 2.10; the equations tests/solver/beam_rod_shooting.hpp integrates)
//   n' + f = 0,   m' + r' × n + m̄ = 0   (spatial n, m; f per reference length; m̄ = 0 here),
// the end actions of each element come from its own internal force vector:
// integrating the weak form by parts, ∫ B'_k n ds = [B_k n] + ∫ B_k f ds, and
// the Hermite/Lagrange position functions are 1 at their node and 0 at the
// other end (tangent functions vanish at both ends), so with P_k = R_k − ∫ B_k f ds
// (R the element's internal force vector, BeamTerm::internal_force)
//   n(a) = −P_{r_a},  n(b) = P_{r_b}.
// These are exact for the discrete solution (they are what node equilibrium
// passes from element to element; a cantilever's tip force comes back to
// round-off at every node). The moment: a rigid rotation δθ of the element
// (positions and Hermite tangents rotate, δx_k = δθ × x_k) does no internal
// work, Σ_k x_k × R_k + Σ_i R_θi = 0, so the moment an element exchanges with
// its neighbour through node b is
//   m(b) = R_θb + t_b × P_{t_b},  m(a) = −(R_θa + t_a × P_{t_a})
// (the Hermite tangent DOF is shared by both elements and carries part of the
// moment; Lagrange elements have no tangent term). With R_θmid = 0 (no load at
// the middle node) the element is in rotational balance and
//   m(b) − m(a) + ∫ r' × n ds = 0
// exactly. Inside the element
//   n(s) = n(a) − ∫_a^s f,      m(s) = m(a) − ∫_a^s r' × n,
// evaluated from both ends and blended linearly in ξ (identical for a converged
// state; the blend spreads any residual imbalance smoothly). r is the element's
// current centerline, so n and m vary smoothly along s (constant n and a moment
// linear in r for a point-loaded element).
//
// Moments: C_M Ω is well conditioned (the moments were already good), but
// equilibrium is better still. On the 45° bend (16 Hermite elements, F = 300 /
// 600, 144 samples; tests/solver/beam_resultant_output_test.cpp) the largest
// error in M₁ or ‖M_b‖, relative to max |M| of the shooting solution, is
//   recovered m(s) (here)          2e-6 / 9e-6
//   C_M Ω evaluated at the sample  2.5e-4 / 8.2e-4
//   nearest Gauss point's C_M Ω    8.6e-3 / 1.1e-2   (the output before)
// (forces: 5e-6 / 2.6e-5 of |F| here, 0.43 / 0.70 from the nearest Gauss point),
// so the output takes elastic moments from equilibrium as well. Plastic
// sections keep the committed Gauss-point moment, the one consistent with the
// plastic curvature written beside it (beam_output.hpp).
#include "solver/beams/beam_term.hpp"

#include <Eigen/Core>

#include <span>
#include <vector>

namespace stentsim::solver::beams {

/// A dead line load at its current value: force per unit reference length on
/// `elements` (empty: every element), as BeamLineLoadTerm assembles it.
struct BeamDeadLineLoad {
  Eigen::Vector3d force_per_length = Eigen::Vector3d::Zero();
  std::vector<std::size_t> elements;
};

/// Sum of the line loads acting on element e.
Eigen::Vector3d line_load_on(std::span<const BeamDeadLineLoad> loads, std::size_t e);

/// Spatial resultants along one element by equilibrium (see above).
class ElementResultants {
 public:
  /// `f`: the dead line load on the element (line_load_on).
  ElementResultants(const BeamTerm& beam, const Eigen::VectorXd& u, std::size_t e,
                    const Eigen::Vector3d& f = Eigen::Vector3d::Zero());
  /// Spatial force n and moment m (about the centerline point r(ξ)) at ξ ∈ [−1, 1].
  void at(double xi, Eigen::Vector3d& n, Eigen::Vector3d& m) const;
  /// End actions: n, m at node a (ξ = −1) and b (ξ = +1), from the element's own internal force vector.
  const Eigen::Vector3d& force_a() const { return n_a_; }
  const Eigen::Vector3d& force_b() const { return n_b_; }
  const Eigen::Vector3d& moment_a() const { return m_a_; }
  const Eigen::Vector3d& moment_b() const { return m_b_; }

 private:
  Eigen::Vector3d centerline(const ShapePoint& p) const;
  /// ∫_{−1}^{ξ} (ds/dξ) dξ and ∫_{−1}^{ξ} r (ds/dξ) dξ (Gauss quadrature).
  void integrals(double xi, double& sigma, Eigen::Vector3d& rho) const;

  const ElementReference& ref_;
  BeamTerm::InternalForce in_;
  Eigen::Vector3d f_;
  Eigen::Vector3d n_a_, n_b_, m_a_, m_b_, r_a_, r_b_;
  double sigma_b_ = 0.0;  // ∫ ds over the element, by the quadrature used inside
  Eigen::Vector3d rho_b_;
};

}  // namespace stentsim::solver::beams
