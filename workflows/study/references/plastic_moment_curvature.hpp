#pragma once
// Closed-form moment–curvature path of the elasto-plastic beam section of
// paper App. C (DESIGN.md §5; solver/beams/plastic_bending.hpp) under a
// bending moment of fixed direction: elastic with slope EI up to the yield
// moment M_y0, then linear hardening with slope E_ep·I (H = E_ep/(1 − E_ep/E)
// is built so that EI·HI/(EI + HI) = E_ep·I); unloading from the largest
// moment M_max is elastic with slope EI:
//   κ(M; M_max) = M/EI                                   (M_max ≤ M_y0)
//               = κ_load(M_max) − (M_max − M)/EI         (M_max > M_y0),
//   κ_load(M)   = M_y0/EI + (M − M_y0)/(E_ep·I).
// With isotropic hardening the yield moment after loading to M_max is M_max,
// so unloading stays elastic down to M = −M_max: for 0 ≤ M ≤ M_max the form
// is exact (no reverse yielding). A cantilever under an end moment carries
// that moment uniformly, so its curvature is κ and its end rotation κL.
//
// Header-only (like tube_reference.hpp): the solver's plastic cantilever test
// (tests/solver/beam_plastic_cantilever_test.cpp) and the error study's
// `beam_plastic_rollup` reference use this one formula.
#include <stdexcept>

namespace stentsim::study::reference {

struct PlasticMomentCurvature {
  double E = 0.0;     ///< Young's modulus [MPa]
  double E_ep = 0.0;  ///< elasto-plastic tangent modulus [MPa], 0 < E_ep < E
  double M_y0 = 0.0;  ///< initial yield moment [N·mm]
  double I = 0.0;     ///< second moment of area [mm⁴]

  PlasticMomentCurvature(double E_, double E_ep_, double M_y0_, double I_) : E(E_), E_ep(E_ep_), M_y0(M_y0_), I(I_) {
    if (!(E > 0) || !(E_ep > 0) || !(E_ep < E) || !(M_y0 > 0) || !(I > 0))
      throw std::invalid_argument("PlasticMomentCurvature: need 0 < E_ep < E, M_y0 > 0, I > 0");
  }

  /// Curvature on the monotone loading branch at moment M ≥ 0.
  double loading(double M) const { return M <= M_y0 ? M / (E * I) : M_y0 / (E * I) + (M - M_y0) / (E_ep * I); }

  /// Curvature at moment M after the largest moment M_max (0 ≤ M ≤ M_max).
  double curvature(double M, double M_max) const {
    if (!(M >= 0.0) || !(M <= M_max))
      throw std::invalid_argument("PlasticMomentCurvature: the closed form covers 0 <= M <= M_max (no reverse loading)");
    return M_max <= M_y0 ? M / (E * I) : loading(M_max) - (M_max - M) / (E * I);
  }

  /// Plastic (residual) curvature after loading to M_max: κ_load(M_max) − M_max/EI.
  double plastic_curvature(double M_max) const { return curvature(M_max, M_max) - M_max / (E * I); }
};

}  // namespace stentsim::study::reference
