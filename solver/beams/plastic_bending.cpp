#include "solver/beams/plastic_bending.hpp"

#include "common/error.hpp"

#include <cmath>
#include <numbers>
#include <string>

namespace stentsim::solver::beams {

PlasticBendingLaw PlasticBendingLaw::stent_preset() { return {380000.0, 190000.0, 64000.0, 0.08, 0.06}; }

double PlasticBendingLaw::inertia() const { return std::numbers::pi * std::pow(radius, 4) / 4.0; }

double PlasticBendingLaw::hardening_modulus() const { return E_ep / (1.0 - E_ep / E); }

void PlasticBendingLaw::validate(const char* where) const {
  auto bad = [&](const char* field, const char* what) {
    throw InputError(std::string(where) + ": plastic beam section field '" + field + "' must be " + what);
  };
  if (!(std::isfinite(E) && E > 0.0)) bad("E", "positive and finite");
  if (!(std::isfinite(G) && G > 0.0)) bad("G", "positive and finite");
  if (!(std::isfinite(E_ep) && E_ep > 0.0 && E_ep < E)) bad("E_ep", "in (0, E)");
  if (!(std::isfinite(M_y0) && M_y0 > 0.0)) bad("M_y0", "positive and finite");
  if (!(std::isfinite(radius) && radius > 0.0)) bad("radius", "positive and finite");
}

PlasticBendingResult plastic_bending_return(const PlasticBendingLaw& law, const Eigen::Vector3d& Omega,
                                            const PlasticBendingHistory& committed) {
  const double I = law.inertia();
  const double EI = law.E * I, GIT = law.G * 2.0 * I, HI = law.hardening_modulus() * I;
  PlasticBendingResult r;
  r.history = committed;
  // Torsion: the component on the section's first base vector (beam axis).
  r.M[0] = GIT * Omega[0];
  r.C(0, 0) = GIT;
  // Bending trial state: Ω_b^el,trial = Ω_b − Ω_b^pl,n (components 2, 3).
  const Eigen::Vector2d om_el_trial = Omega.tail<2>() - committed.plastic_curvature.tail<2>();
  const Eigen::Vector2d M_trial = EI * om_el_trial;
  const double m_trial = M_trial.norm();
  const double M_y = law.M_y0 + HI * committed.accumulated;
  r.phi_trial = m_trial - M_y;
  if (r.phi_trial <= 0.0) {
    r.M.tail<2>() = M_trial;
    r.C.bottomRightCorner<2, 2>() = EI * Eigen::Matrix2d::Identity();
  } else {
    r.yielding = true;
    const double dgamma = r.phi_trial / (EI + HI);
    const Eigen::Vector2d n = M_trial / m_trial;
    const double m = m_trial - EI * dgamma;  // = M_y0 + H·I·(Ω̄_n + Δγ)
    r.M.tail<2>() = m * n;
    r.history.plastic_curvature.tail<2>() += dgamma * n;
    r.history.accumulated += dgamma;
    // dM_b/dΩ_b = EI·HI/(EI+HI) n nᵀ + (m/‖M_trial‖)·EI (1 − n nᵀ).
    const Eigen::Matrix2d nn = n * n.transpose();
    r.C.bottomRightCorner<2, 2>() =
        (EI * HI / (EI + HI)) * nn + (m / m_trial) * EI * (Eigen::Matrix2d::Identity() - nn);
  }
  r.history.plastic_curvature[0] = 0.0;
  const Eigen::Vector2d om_el = Omega.tail<2>() - r.history.plastic_curvature.tail<2>();
  r.elastic_energy = 0.5 * (GIT * Omega[0] * Omega[0] + EI * om_el.squaredNorm());
  return r;
}

}  // namespace stentsim::solver::beams
