#pragma once
// Reference (stress-free) data of one beam element: shape functions at the
// quadrature points, reference arc length and reference strains.
//
// Two interpolations (Meier, Popp & Wall 2019, Arch. Comput. Methods Eng. 26,
// §3; 4C Beam3r):
// - Hermite "Herm2Line3": cubic Hermite centerline through the end positions
//   r_a, r_b and tangents t_a, t_b (t = ∂r/∂s, s the reference arc length),
//     r(ξ) = H1 r_a + (l/2) H2 t_a + H3 r_b + (l/2) H4 t_b,  ξ ∈ [−1, 1],
//   with l the reference arc length of the element (found by fixed-point
//   iteration, as the tangent scaling depends on it); triads from 3 nodes
//   (a at ξ = −1, b at ξ = +1, mid at ξ = 0), quadratic Lagrange weights.
// - Lagrange "Line2": linear centerline and triads from the 2 end nodes,
//   one-point integration.
// Triads are interpolated by Crisfield & Jelenić (1999, Proc. R. Soc. A 455,
// eq. 4.1–4.4): Λ(ξ) = Λ_r exp(S(Σ N_i ψ_i)), Λ_r exp(S(ψ_i)) = Λ_i, with the
// reference triad Λ_r = Λ_I exp(½ log(Λ_Iᵀ Λ_J)) from the middle nodes I, J
// (I = J = mid for 3 nodes; I = a, J = b for 2 nodes). This is objective and
// path independent because it uses only the current nodal triads.
#include "solver/beams/section.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <vector>

namespace stentsim::solver::beams {

enum class BeamInterpolation { hermite3, lagrange2 };

/// Gauss–Legendre points and weights on [−1, 1].
void gauss_legendre(int n, std::vector<double>& points, std::vector<double>& weights);

/// Shape data at one parameter ξ. NC nodal centerline vectors (Hermite:
/// r_a, t_a, r_b, t_b; Lagrange: r_a, r_b), NT nodal triads (Hermite: a, b,
/// mid; Lagrange: a, b). Derivatives are with respect to reference arc length.
struct ShapePoint {
  double xi = 0.0;
  double weight_ds = 0.0;          // Gauss weight × ds/dξ (0 for sample points)
  std::array<double, 4> B{}, dB{};  // centerline functions (tangent scaling included)
  std::array<double, 3> N{}, dN{};  // triad weights
  Eigen::Vector3d Gamma0 = Eigen::Vector3d::Zero();  // Λ₀ᵀ r₀' (≈ E₁)
  Eigen::Vector3d Kappa0 = Eigen::Vector3d::Zero();  // reference curvature
};

struct ElementReference {
  BeamInterpolation kind = BeamInterpolation::hermite3;
  double length = 0.0;  // reference arc length l
  std::array<Eigen::Vector3d, 4> x0{};      // reference centerline vectors
  std::array<Eigen::Quaterniond, 3> q0{};   // reference nodal triads
  std::vector<ShapePoint> points;           // quadrature points for stiffness and loads

  int centerline_vectors() const { return kind == BeamInterpolation::hermite3 ? 4 : 2; }
  int triad_nodes() const { return kind == BeamInterpolation::hermite3 ? 3 : 2; }
  /// Shape data (without weight) at any ξ, including Γ₀ and K₀.
  ShapePoint at(double xi) const;
};

/// Builds the reference data. Hermite: x0 = {X_a, T_a, X_b, T_b} with unit
/// reference tangents, q0 = {Λ_a, Λ_b, Λ_mid}; Lagrange: x0 = {X_a, X_b},
/// q0 = {Λ_a, Λ_b}. `gauss_points` = 0 picks the default: Hermite 3 (the
/// lowest stable Gauss rule: 3 × 6 strains ≥ 21 − 6 rigid modes; 2 points
/// leave spurious zero-energy modes; 3 points integrate the linearized energy
/// of a straight element exactly and gave the smallest roll-up errors of 3, 4,
/// 5 points), Lagrange 1 (reduced, as 4C's Line2).
ElementReference make_element_reference(BeamInterpolation kind, const std::array<Eigen::Vector3d, 4>& x0,
                                        const std::array<Eigen::Quaterniond, 3>& q0, int gauss_points = 0);

}  // namespace stentsim::solver::beams
