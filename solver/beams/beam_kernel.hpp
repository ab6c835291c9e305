#pragma once
// The Simo–Reissner element energy, residual and tangent (one element).
//
// Strains (Simo & Vu-Quoc 1986; paper Section 2.2, App. C):
//   Γ = Λᵀ r' − Λ₀ᵀ r₀'   (axial, two shear; Λ₀ᵀ r₀' = E₁ for triads aligned with
//                          the reference tangent — subtracting the interpolated
//                          reference value keeps curved references exactly
//                          stress-free, as 4C does),
//   Ω = K − K₀ with S(K) = Λᵀ Λ' (torsion, two bending),
//   Π = ∫ ½ (Γ·C_F Γ + Ω·C_M Ω) ds.
// Variations: additive DOFs x (positions, Hermite tangents) enter r' linearly;
// nodal triads are perturbed multiplicatively, Λ_i(h_i) = exp(S(h_i)) Λ_i
// (spatial convention, rotation.hpp). With Π̂(x, h) the energy of the perturbed
// state, the residual is R = ∇Π̂ at h = 0 and the consistent tangent of the
// spatial multiplicative update is
//   K = ∇²Π̂ − ½ blockdiag_i S(∂Π̂/∂h_i)
// since exp(S(a e_i)) exp(S(ε e_j)) = exp(S(a e_i + ε e_j + ½ a ε e_i × e_j + …))
// (Baker–Campbell–Hausdorff); K is non-symmetric away from equilibrium.
// ∇²Π̂ over the rotations comes from Jet<3·NT>; the blocks with x by hand:
//   ∂Π/∂x_k = ∫ B'_k n ds, n = Λ C_F Γ,  ∂²Π/∂x_k∂x_l = ∫ B'_k B'_l Λ C_F Λᵀ ds,
//   ∂²Π/∂x_k∂h = ∫ B'_k ∂n/∂h ds.
#include "solver/beams/element_reference.hpp"
#include "solver/beams/jet.hpp"
#include "solver/beams/rotation.hpp"
#include "solver/beams/section.hpp"

#include <Eigen/Core>

#include <array>

namespace stentsim::solver::beams {

/// Crisfield–Jelenić triad field of one element: Λ_r and the local rotation
/// vectors ψ_i with Λ_r exp(S(ψ_i)) = Λ_i.
template <class S, int NT>
struct TriadField {
  Quat<S> qr;
  std::array<V3<S>, NT> psi;
};

template <class S, int NT>
TriadField<S, NT> triad_field(const std::array<Quat<S>, NT>& q) {
  TriadField<S, NT> f;
  if constexpr (NT == 3) {
    // I = J = the middle node (index 2): Λ_r = Λ_mid, ψ_mid = 0.
    f.qr = q[2];
    const Quat<S> rc = qconj(f.qr);
    f.psi[0] = qlog(qmul(rc, q[0]));
    f.psi[1] = qlog(qmul(rc, q[1]));
    f.psi[2] = {S(0.0), S(0.0), S(0.0)};
  } else {
    // I = a, J = b: Λ_r = Λ_a exp(½ Φ), Φ = log(Λ_aᵀ Λ_b); ψ_a = −Φ/2, ψ_b = Φ/2.
    const V3<S> phi = qlog(qmul(qconj(q[0]), q[1]));
    const V3<S> half{0.5 * phi[0], 0.5 * phi[1], 0.5 * phi[2]};
    f.qr = qmul(q[0], qexp(half));
    f.psi[0] = {-half[0], -half[1], -half[2]};
    f.psi[1] = half;
  }
  return f;
}

/// Λ and K (S(K) = ΛᵀΛ') at a point with triad weights N, dN/ds.
template <class S, int NT>
void triad_at(const TriadField<S, NT>& f, const std::array<double, 3>& N, const std::array<double, 3>& dN,
              M3<S>& Lambda, V3<S>& K) {
  V3<S> psi{S(0.0), S(0.0), S(0.0)}, dpsi{S(0.0), S(0.0), S(0.0)};
  for (int i = 0; i < NT; ++i)
    for (int c = 0; c < 3; ++c) {
      psi[c] += N[i] * f.psi[i][c];
      dpsi[c] += dN[i] * f.psi[i][c];
    }
  Lambda = qmat(qmul(f.qr, qexp(psi)));
  K = right_jacobian_times(psi, dpsi);
}

/// Section state at one point (double): the quantities of objectivity tests and output.
struct SectionState {
  double xi = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d triad = Eigen::Matrix3d::Identity();
  Eigen::Vector3d Gamma = Eigen::Vector3d::Zero(), Omega = Eigen::Vector3d::Zero();
  Eigen::Vector3d F = Eigen::Vector3d::Zero(), M = Eigen::Vector3d::Zero();  // material resultants
  // Elasto-plastic sections (plastic_bending.hpp): the state after the return
  // from the history passed in; zero for elastic sections.
  PlasticBendingHistory plastic;
  bool yielding = false;
  double stored_energy_density = 0.0;  // ½ Γ·F + elastic bending/torsion energy [N]
};

template <int NC, int NT>
SectionState section_state(const ShapePoint& p, const BeamSection& sec, const std::array<Eigen::Vector3d, 4>& x,
                           const std::array<Eigen::Quaterniond, 3>& q, const PlasticBendingHistory* history = nullptr) {
  std::array<Quat<double>, NT> qq;
  for (int i = 0; i < NT; ++i) qq[i] = qconst<double>(q[i]);
  const auto f = triad_field<double, NT>(qq);
  M3<double> L;
  V3<double> K;
  triad_at<double, NT>(f, p.N, p.dN, L, K);
  SectionState s;
  s.xi = p.xi;
  Eigen::Vector3d dr = Eigen::Vector3d::Zero();
  for (int k = 0; k < NC; ++k) {
    s.position += p.B[k] * x[k];
    dr += p.dB[k] * x[k];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s.triad(i, j) = L[3 * i + j];
  s.Gamma = s.triad.transpose() * dr - p.Gamma0;
  s.Omega = Eigen::Vector3d(K[0], K[1], K[2]) - p.Kappa0;
  s.F = sec.CF.cwiseProduct(s.Gamma);
  if (sec.plastic) {
    const PlasticBendingResult r =
        plastic_bending_return(*sec.plastic, s.Omega, history ? *history : PlasticBendingHistory{});
    s.M = r.M;
    s.plastic = r.history;
    s.yielding = r.yielding;
    s.stored_energy_density = 0.5 * s.Gamma.dot(s.F) + r.elastic_energy;
  } else {
    s.M = sec.CM.cwiseProduct(s.Omega);
    s.stored_energy_density = 0.5 * (s.Gamma.dot(s.F) + s.Omega.dot(s.M));
  }
  return s;
}

template <int NC, int NT>
double element_energy(const ElementReference& ref, const BeamSection& sec, const std::array<Eigen::Vector3d, 4>& x,
                      const std::array<Eigen::Quaterniond, 3>& q, const PlasticBendingHistory* history = nullptr) {
  // Stored (elastic) energy; for plastic sections from the return of each
  // Gauss point's committed history `history[g]`.
  double e = 0.0;
  for (std::size_t g = 0; g < ref.points.size(); ++g) {
    const ShapePoint& p = ref.points[g];
    const SectionState s = section_state<NC, NT>(p, sec, x, q, history ? &history[g] : nullptr);
    e += p.weight_ds * s.stored_energy_density;
  }
  return e;
}

/// Residual and tangent in the split ordering [x_0 … x_{NC−1}, θ_0 … θ_{NT−1}]
/// (3 components each).
template <int NC, int NT>
struct ElementSystem {
  static constexpr int n = 3 * (NC + NT);
  Eigen::Matrix<double, n, 1> R = Eigen::Matrix<double, n, 1>::Zero();
  Eigen::Matrix<double, n, n> K = Eigen::Matrix<double, n, n>::Zero();
  double energy = 0.0;
};

template <int NC, int NT>
void element_system(const ElementReference& ref, const BeamSection& sec, const std::array<Eigen::Vector3d, 4>& x,
                    const std::array<Eigen::Quaterniond, 3>& q, ElementSystem<NC, NT>& out,
                    const PlasticBendingHistory* committed = nullptr, PlasticBendingHistory* trial = nullptr,
                    double* plastic_work = nullptr) {
  constexpr int NH = 3 * NT;
  constexpr int NX = 3 * NC;
  using J = Jet<NH>;
  using G = Grad<NH>;
  // Perturbed nodal triads exp(S(h_i)) Λ_i, h = 0 as Jet variables.
  std::array<Quat<J>, NT> qq;
  for (int i = 0; i < NT; ++i) {
    const V3<J> h{J::variable(0.0, 3 * i), J::variable(0.0, 3 * i + 1), J::variable(0.0, 3 * i + 2)};
    qq[i] = qmul(qexp_second_order(h), qconst<J>(q[i]));
  }
  const auto field = triad_field<J, NT>(qq);
  const M3<J> Lr = qmat(field.qr);  // Λ_r
  std::array<G, 9> Lrg;
  Eigen::Matrix3d Lrv;
  for (int k = 0; k < 9; ++k) Lrg[k] = G(Lr[k]), Lrv(k / 3, k % 3) = Lr[k].v;
  // Nodes with ψ ≡ 0 (the Hermite middle node) are skipped in the sums.
  constexpr int NPSI = NT == 3 ? 2 : NT;

  J energy(0.0);
  Eigen::Matrix<double, NX, 1> gx = Eigen::Matrix<double, NX, 1>::Zero();
  Eigen::Matrix<double, NX, NX> Hxx = Eigen::Matrix<double, NX, NX>::Zero();
  Eigen::Matrix<double, NX, NH> Hxh = Eigen::Matrix<double, NX, NH>::Zero();
  if (plastic_work) *plastic_work = 0.0;
  for (std::size_t gp = 0; gp < ref.points.size(); ++gp) {
    const ShapePoint& p = ref.points[gp];
    // Λ = Λ_r exp(S(ψ)), ψ = Σ N_i ψ_i; Γ = exp(S(ψ))ᵀ Λ_rᵀ r' − Γ₀; K = J_r(ψ) ψ'.
    V3<J> psi{J(0.0), J(0.0), J(0.0)}, dpsi{J(0.0), J(0.0), J(0.0)};
    for (int i = 0; i < NPSI; ++i)
      for (int c = 0; c < 3; ++c) {
        psi[c] += field.psi[i][c] * p.N[i];
        dpsi[c] += field.psi[i][c] * p.dN[i];
      }
    const J t2 = dot(psi, psi);
    const J alpha = rotation_coefficient(0, t2), a = rotation_coefficient(1, t2), b = rotation_coefficient(2, t2);
    Eigen::Vector3d dr = Eigen::Vector3d::Zero();
    for (int k = 0; k < NC; ++k) dr += p.dB[k] * x[k];
    V3<J> rho;
    for (int i = 0; i < 3; ++i) rho[i] = Lr[i] * dr[0] + Lr[3 + i] * dr[1] + Lr[6 + i] * dr[2];
    const V3<J> pr = cross(psi, rho), ppr = cross(psi, pr);
    const V3<J> pk = cross(psi, dpsi), ppk = cross(psi, pk);
    V3<J> Gam, Om, F, M;
    for (int i = 0; i < 3; ++i) {
      Gam[i] = rho[i] - alpha * pr[i] + a * ppr[i] - p.Gamma0[i];
      Om[i] = dpsi[i] - a * pk[i] + b * ppk[i] - p.Kappa0[i];
      F[i] = Gam[i] * sec.CF[i];
      M[i] = Om[i] * sec.CM[i];
    }
    J pi(0.0);
    if (sec.plastic) {
      // Elasto-plastic moment (plastic_bending.hpp). Within a load step the
      // radial return is the gradient of an incremental potential W(Ω) with
      // dW/dΩ = M and d²W/dΩ² = C (the symmetric algorithmic tangent), so its
      // second-order expansion about the current Ω, in the perturbation jets
      // dΩ = Ω − Ω(h=0), gives the consistent residual (M·dΩ) and Hessian
      // (dΩᵀ C dΩ + M·d²Ω); the constant is the stored elastic energy.
      const Eigen::Vector3d Omv(Om[0].v, Om[1].v, Om[2].v);
      const PlasticBendingResult r =
          plastic_bending_return(*sec.plastic, Omv, committed ? committed[gp] : PlasticBendingHistory{});
      if (trial) trial[gp] = r.history;
      // Plastic work of the step, ∫ M_b·dΩ_pl = ∫ M_y(Ω̄) dΩ̄ (‖M_b‖ = M_y while
      // flowing along n): exact for linear hardening, M_y at the mid value of Ω̄.
      if (plastic_work && committed) {
        const double a0 = committed[gp].accumulated, da = r.history.accumulated - a0;
        const double HI = sec.plastic->hardening_modulus() * sec.plastic->inertia();
        *plastic_work += p.weight_ds * (sec.plastic->M_y0 + HI * (a0 + 0.5 * da)) * da;
      }
      V3<J> dOm;
      for (int i = 0; i < 3; ++i) dOm[i] = Om[i] - Omv[i];
      pi = 0.5 * dot(Gam, F) + r.elastic_energy;
      for (int i = 0; i < 3; ++i) {
        J Ci = r.C(i, 0) * dOm[0] + r.C(i, 1) * dOm[1] + r.C(i, 2) * dOm[2];
        pi += (r.M[i] + 0.5 * Ci) * dOm[i];
      }
    } else {
      pi = 0.5 * (dot(Gam, F) + dot(Om, M));
    }
    pi *= p.weight_ds;
    energy += pi;
    // Spatial force n = Λ_r (F + α ψ×F + a ψ×(ψ×F)) to first order, and Λ C_F Λᵀ.
    const V3<G> psig{G(psi[0]), G(psi[1]), G(psi[2])}, Fg{G(F[0]), G(F[1]), G(F[2])};
    const G alg(alpha), ag(a);
    const V3<G> pF = cross(psig, Fg), ppF = cross(psig, pF);
    V3<G> w;
    for (int i = 0; i < 3; ++i) w[i] = Fg[i] + alg * pF[i] + ag * ppF[i];
    Eigen::Vector3d nv;
    Eigen::Matrix<double, 3, NH> ng;
    for (int i = 0; i < 3; ++i) {
      const G ni = Lrg[3 * i] * w[0] + Lrg[3 * i + 1] * w[1] + Lrg[3 * i + 2] * w[2];
      nv[i] = ni.v;
      ng.row(i) = ni.g.transpose();
    }
    const Eigen::Matrix3d Lv = Lrv * quat_exp(Eigen::Vector3d(psi[0].v, psi[1].v, psi[2].v)).toRotationMatrix();
    const Eigen::Matrix3d C = Lv * sec.CF.asDiagonal() * Lv.transpose();
    for (int k = 0; k < NC; ++k) {
      const double wk = p.weight_ds * p.dB[k];
      gx.template segment<3>(3 * k) += wk * nv;
      Hxh.template block<3, NH>(3 * k, 0) += wk * ng;
      for (int l = 0; l < NC; ++l) Hxx.template block<3, 3>(3 * k, 3 * l) += (wk * p.dB[l]) * C;
    }
  }
  out.energy = energy.v;
  out.R.template head<NX>() = gx;
  out.R.template tail<NH>() = energy.g;
  out.K.template topLeftCorner<NX, NX>() = Hxx;
  out.K.template topRightCorner<NX, NH>() = Hxh;
  out.K.template bottomLeftCorner<NH, NX>() = Hxh.transpose();
  Eigen::Matrix<double, NH, NH> Khh = energy.hessian();
  for (int i = 0; i < NT; ++i)
    Khh.template block<3, 3>(3 * i, 3 * i) -= 0.5 * skew(energy.g.template segment<3>(3 * i));
  out.K.template bottomRightCorner<NH, NH>() = Khh;
}

}  // namespace stentsim::solver::beams
