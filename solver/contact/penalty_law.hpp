#pragma once
// Penalty potential per unit length (beam-to-surface, ε in N/mm²) or per unit
// area (surface-to-surface, ε in N/mm³) as a function of the gap g
// (paper 2.5: Π = ∫ ε/2 ⟨−g⟩² ds). The contact force per length or area is
// f = −φ'(g) ≥ 0.
// - linear (smoothing g0 = 0): φ = ε g²/2 for g < 0, else 0; a kink of φ'' at 0.
// - C¹-smoothed (g0 > 0), quadratic regularization of the force near g = 0
//   (as 4C's regularized beam contact laws): f = ε (g0/2 − g) for g ≤ 0,
//   f = ε (g0 − g)²/(2 g0) on 0 < g < g0, 0 beyond; f and f' are continuous,
//   and the penetration at a line load q is q/ε − g0/2 (instead of q/ε).
namespace stentsim::solver::contact {

struct PenaltyLaw {
  double epsilon = 0.0;
  double smoothing = 0.0;  // g0

  /// Points with g below this limit carry force.
  double active_limit() const { return smoothing; }
  /// φ(g), φ'(g), φ''(g).
  void eval(double g, double& phi, double& d1, double& d2) const {
    const double e = epsilon, g0 = smoothing;
    if (g0 <= 0.0) {
      if (g < 0) phi = 0.5 * e * g * g, d1 = e * g, d2 = e;
      else phi = d1 = d2 = 0.0;
      return;
    }
    if (g <= 0) {
      phi = e * g0 * g0 / 6.0 - 0.5 * e * g0 * g + 0.5 * e * g * g;
      d1 = -0.5 * e * g0 + e * g;
      d2 = e;
    } else if (g < g0) {
      const double r = g0 - g;
      phi = e * r * r * r / (6.0 * g0);
      d1 = -e * r * r / (2.0 * g0);
      d2 = e * r / g0;
    } else {
      phi = d1 = d2 = 0.0;
    }
  }
};

}  // namespace stentsim::solver::contact
