#pragma once
// Elasto-plastic bending of a circular beam section (paper App. C; DESIGN.md §5, §8).
//
// The material moment M = C_M Ω is split on the section frame's first base
// vector d1 (the beam axis, e₁ = [1,0,0] in material components — never the
// global x axis): torsion M_t = GI_T Ω₁ stays elastic; bending
//   Ω_b = Ω_b^el + Ω_b^pl,  M_b = EI Ω_b^el,
//   Φ = ‖M_b‖ − (M_y0 + H·I·Ω̄_pl) ≤ 0,  H = E_ep / (1 − E_ep/E),
//   Ω̇_b^pl = γ e, e = Ω_b^el/‖Ω_b^el‖,  Ω̄̇_pl = γ,  γ ≥ 0, γΦ = 0.
// Backward Euler gives a radial return (the flow direction is the trial
// direction): Δγ = Φ_trial / (EI + H·I). Axial and shear resultants are
// elastic and not handled here.
#include <Eigen/Core>

namespace stentsim::solver::beams {

struct PlasticBendingLaw {
  double E = 0.0;       // Young's modulus [MPa]
  double G = 0.0;       // shear modulus [MPa]
  double E_ep = 0.0;    // elasto-plastic tangent modulus [MPa]
  double M_y0 = 0.0;    // initial yield moment [N·mm]
  double radius = 0.0;  // section radius R [mm]

  /// The stent preset (issue 9): E = 380000, G = 190000, E_ep = 64000 MPa,
  /// M_y0 = 0.08 N·mm, R = 0.06 mm (so GI_T = EI as App. C requires).
  static PlasticBendingLaw stent_preset();

  double inertia() const;          // I = πR⁴/4 [mm⁴]
  double hardening_modulus() const;  // H = E_ep/(1 − E_ep/E) [MPa]
  /// Throws InputError naming `where` unless 0 < E_ep < E, G, M_y0, R > 0.
  void validate(const char* where) const;
};

/// Committed (or trial) state of one Gauss point.
struct PlasticBendingHistory {
  Eigen::Vector3d plastic_curvature = Eigen::Vector3d::Zero();  // Ω_b^pl (material components, ⊥ e₁) [1/mm]
  double accumulated = 0.0;                                      // Ω̄_pl [1/mm]
};

struct PlasticBendingResult {
  Eigen::Vector3d M = Eigen::Vector3d::Zero();       // material moment, torsion + bending [N·mm]
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();       // algorithmic tangent dM/dΩ [N·mm²]
  PlasticBendingHistory history;                     // trial history after the return
  double phi_trial = 0.0;                            // Φ of the elastic trial state [N·mm]
  bool yielding = false;                             // Φ_trial > 0 (plastic step)
  double elastic_energy = 0.0;                       // ½ Ω_el·C_M Ω_el per length [N]
};

/// Return mapping at one Gauss point for the total curvature Ω (material
/// components, reference curvature already subtracted) from the committed
/// history. The tangent is the consistent (algorithmic) one of the radial return.
PlasticBendingResult plastic_bending_return(const PlasticBendingLaw& law, const Eigen::Vector3d& Omega,
                                            const PlasticBendingHistory& committed);

}  // namespace stentsim::solver::beams
