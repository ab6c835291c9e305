#include "solver/beams/beam_resultants.hpp"

#include <algorithm>

namespace stentsim::solver::beams {

Eigen::Vector3d line_load_on(std::span<const BeamDeadLineLoad> loads, std::size_t e) {
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  for (const BeamDeadLineLoad& l : loads)
    if (l.elements.empty() || std::find(l.elements.begin(), l.elements.end(), e) != l.elements.end())
      f += l.force_per_length;
  return f;
}

ElementResultants::ElementResultants(const BeamTerm& beam, const Eigen::VectorXd& u, std::size_t e,
                                     const Eigen::Vector3d& f)
    : ref_(beam.reference(e)), in_(beam.internal_force(u, e)), f_(f) {
  const int nc = ref_.centerline_vectors();
  // P_k = R_k − ∫ B_k f ds with the quadrature BeamLineLoadTerm assembles with.
  std::array<Eigen::Vector3d, 4> P;
  for (int k = 0; k < nc; ++k) {
    P[k] = in_.force[k];
    for (const ShapePoint& p : ref_.points) P[k] -= p.weight_ds * p.B[k] * f_;
  }
  if (ref_.kind == BeamInterpolation::hermite3) {
    // x = (r_a, t_a, r_b, t_b)
    n_a_ = -P[0];
    n_b_ = P[2];
    m_a_ = -(in_.moment[0] + in_.x[1].cross(P[1]));
    m_b_ = in_.moment[1] + in_.x[3].cross(P[3]);
    r_a_ = in_.x[0];
    r_b_ = in_.x[2];
  } else {
    n_a_ = -P[0];
    n_b_ = P[1];
    m_a_ = -in_.moment[0];
    m_b_ = in_.moment[1];
    r_a_ = in_.x[0];
    r_b_ = in_.x[1];
  }
  rho_b_.setZero();
  if (!f_.isZero(0.0)) integrals(1.0, sigma_b_, rho_b_);
}

Eigen::Vector3d ElementResultants::centerline(const ShapePoint& p) const {
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  for (int k = 0; k < ref_.centerline_vectors(); ++k) r += p.B[k] * in_.x[k];
  return r;
}

void ElementResultants::integrals(double xi, double& sigma, Eigen::Vector3d& rho) const {
  // ds/dξ = 1/(dN_b/ds − dN_a/ds): the triad weights of a and b differ by ξ
  // (Hermite: ½ξ(ξ+1) − ½ξ(ξ−1); Lagrange: ½(1+ξ) − ½(1−ξ)), whose ξ-derivative is 1.
  static const auto rule = [] {
    std::pair<std::vector<double>, std::vector<double>> r;
    gauss_legendre(8, r.first, r.second);
    return r;
  }();
  sigma = 0.0;
  rho.setZero();
  const double half = 0.5 * (xi + 1.0);
  if (half <= 0.0) return;
  for (std::size_t i = 0; i < rule.first.size(); ++i) {
    const ShapePoint p = ref_.at(-1.0 + half * (rule.first[i] + 1.0));
    const double w = half * rule.second[i] / (p.dN[1] - p.dN[0]);
    sigma += w;
    rho += w * centerline(p);
  }
}

void ElementResultants::at(double xi, Eigen::Vector3d& n, Eigen::Vector3d& m) const {
  const Eigen::Vector3d r = centerline(ref_.at(xi));
  // from a: n = n_a − σ f,  m = m_a − (r − r_a) × n_a + (σ r − ρ) × f
  // from b: n = n_b + (σ_b − σ) f,  m = m_b + (r_b − r) × n_b + ((σ − σ_b) r + ρ_b − ρ) × f
  // with σ(ξ) = ∫_a^ξ ds, ρ(ξ) = ∫_a^ξ r ds (∫ σ dr integrated by parts).
  double sigma = 0.0;
  Eigen::Vector3d rho = Eigen::Vector3d::Zero();
  if (!f_.isZero(0.0)) integrals(xi, sigma, rho);
  const Eigen::Vector3d nA = n_a_ - sigma * f_, nB = n_b_ + (sigma_b_ - sigma) * f_;
  const Eigen::Vector3d mA = m_a_ - (r - r_a_).cross(n_a_) + (sigma * r - rho).cross(f_);
  const Eigen::Vector3d mB = m_b_ + (r_b_ - r).cross(n_b_) + ((sigma - sigma_b_) * r + rho_b_ - rho).cross(f_);
  const double w = 0.5 * (xi + 1.0);
  n = (1.0 - w) * nA + w * nB;
  m = (1.0 - w) * mA + w * mB;
}

}  // namespace stentsim::solver::beams
