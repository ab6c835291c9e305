#pragma once
// Projection of a point onto a contact face along a given direction (the
// surface-to-surface gap, surface_to_surface_pair.hpp): find (ξ1, ξ2, α) with
//   F = x(ξ) − p − α d = 0,  x(ξ) = Σ N_l x_l,
// so the face point x(ξ) lies on the ray p + α d. With a unit d, α is the
// signed distance from p to the face along d (positive ahead of p).
//
// Derivatives of α with respect to v = (p, d, x_1..x_nf) follow from the
// implicit function theorem on F = 0, as in normal_projection.hpp, through
// L = α + λᵀF, λ = −J⁻ᵀ e_α, y = (ξ1, ξ2, α), J = ∂F/∂y = [x,1  x,2  −d]:
//   α_v = λᵀ F_v:  α_p = −λ,  α_d = −α λ,  α_{x_l} = N_l λ,
//   α_vv = L_yvᵀ Y + Yᵀ L_yv + Yᵀ L_yy Y,  Y = −J⁻¹ F_v  (L_vv = 0: F is linear in v at fixed y),
//   L_yy: (ξa, ξb) = λ·x,ab, zero in α;  L_yv: (ξa, x_l) = N_l,a λᵀ,  (α, d) = −λᵀ.
#include <Eigen/Core>

#include <array>

#include "solver/contact/contact_surface.hpp"
#include "solver/contact/normal_projection.hpp"

namespace stentsim::solver::contact {

struct DirectionProjection {
  ProjectionKind kind = ProjectionKind::not_converged;
  std::array<double, 2> xi{};
  double alpha = 0.0;                // x(ξ) = p + α d
  Vec3 face_normal = Vec3::Zero();   // unit x,1 × x,2 at ξ (outward: ContactSurface orients faces)
};

/// Projects p along d onto face `face` of `s` (current state of s.update()).
/// `inside_tolerance` widens the reference face for the inside test.
DirectionProjection project_along_direction(const ContactSurface& s, int face, const Vec3& p, const Vec3& d,
                                            double inside_tolerance = 1e-9);

/// First (and with `second`, second) derivatives of α at a converged projection
/// with respect to v = (p[3], d[3], x_l[3 nf]) (size 6 + 3 nf).
void direction_gap_derivatives(const ContactSurface& s, int face, const DirectionProjection& pr, const Vec3& d, bool second,
                               GapDerivatives& out);

}  // namespace stentsim::solver::contact
