#pragma once
// Projection of a point onto a contact face along the interpolated field of
// averaged nodal normals (Steinbrecher, Popp & Meier 2022, beam-to-surface
// contact): find (ξ1, ξ2, α) with
//   F = x(ξ) + α n(ξ) − p = 0,  x(ξ) = Σ N_k x_k,  n(ξ) = Σ N_k n_k,
// and the signed distance d = α |n(ξ)| (positive on the side the normals point
// to). Unlike a closest-point projection, the direction field is continuous
// across face edges, so the gap and its force direction do not jump where a
// point seen from the concave side crosses the bisector of two faces.
//
// Derivatives of d with respect to v = (p, x_1..x_nf, n_1..n_nf) follow from
// the implicit function theorem on F = 0 through the Lagrangian
// L = d + λᵀF, λ = −J_y⁻ᵀ d_yᵀ, y = (ξ1, ξ2, α), J_y = ∂F/∂y:
//   D_v = L_v,  D_vv = L_vv + L_vy Y + Yᵀ L_yv + Yᵀ L_yy Y,  Y = −J_y⁻¹ F_v.
#include <Eigen/Core>

#include <array>

#include "solver/contact/contact_surface.hpp"

namespace stentsim::solver::contact {

enum class ProjectionKind { inside, outside, not_converged };
inline const char* projection_kind_name(ProjectionKind k) {
  return k == ProjectionKind::inside ? "inside" : k == ProjectionKind::outside ? "outside" : "not converged";
}

struct NormalProjection {
  ProjectionKind kind = ProjectionKind::not_converged;
  std::array<double, 2> xi{};
  double alpha = 0.0;
  double distance = 0.0;  // d = α |n(ξ)|
  Vec3 direction = Vec3::Zero();  // n(ξ)/|n(ξ)|: the contact force direction on the point
};

/// Projects p onto face `face` of `s` (current state of s.update()).
/// `inside_tolerance` widens the reference face for the inside test.
NormalProjection project_along_normals(const ContactSurface& s, int face, const Vec3& p, double inside_tolerance = 1e-9);

/// First and second derivatives of d at a converged projection with respect to
/// v = (p[3], x_k[3 nf], n_k[3 nf]) (size 3 + 6 nf).
struct GapDerivatives {
  Eigen::VectorXd grad;
  Eigen::MatrixXd hess;
};
void gap_derivatives(const ContactSurface& s, int face, const NormalProjection& pr, bool second, GapDerivatives& out);

/// What the gap-variation form of contact needs at a converged projection:
/// the unit normal n̂ = n(ξ)/|n(ξ)| the force acts along, the face's shape
/// values N_k there, and (tangent) their derivatives and D_v with respect to
/// v = (p, x_k, n_k): ∂n̂/∂v = (P/ρ)(Σ_k n_k ∂N_k/∂v + Σ_k N_k ∂n_k/∂v),
/// ∂N_k/∂v = N_k,a ∂ξ_a/∂v, ∂ξ/∂v from Y = −J_y⁻¹ F_v.
struct NormalFieldDerivatives {
  Vec3 normal = Vec3::Zero();
  std::array<double, 6> n{};
  Eigen::VectorXd gap_grad;   // D_v (N)
  Eigen::MatrixXd dnormal;    // 3 x N
  Eigen::MatrixXd dshape;     // nf x N
};
void normal_field_derivatives(const ContactSurface& s, int face, const NormalProjection& pr, bool tangent,
                              NormalFieldDerivatives& out);

}  // namespace stentsim::solver::contact
