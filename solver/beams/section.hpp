#pragma once
// Elastic cross-section of a Simo–Reissner beam (paper App. C, eq. C.1):
// F = C_F Γ, M = C_M Ω with C_F = diag(EA, GA₂, GA₃), C_M = diag(GI_T, EI₂, EI₃),
// section axes (d1 = centerline tangent, d2, d3) of the triad.
#include "solver/beams/plastic_bending.hpp"

#include <Eigen/Core>

#include <optional>

#include <string>

namespace stentsim::solver::beams {

struct BeamSection {
  Eigen::Vector3d CF = Eigen::Vector3d::Zero();  // EA, GA₂, GA₃ [N]
  Eigen::Vector3d CM = Eigen::Vector3d::Zero();  // GI_T, EI₂, EI₃ [N·mm²]
  double area = 0.0;                             // A [mm²], for stresses
  double radius = 0.0;                           // outer-fibre distance [mm] (0: unknown)
  double bending_inertia = 0.0;                  // I = I₂ (= I₃ for circles) [mm⁴]
  /// Elasto-plastic bending (App. C; circular sections only, DESIGN.md §8):
  /// when set, the moment comes from its return mapping instead of C_M Ω.
  std::optional<PlasticBendingLaw> plastic;

  /// Circular section of radius R: A = πR², I₂ = I₃ = πR⁴/4, I_T = πR⁴/2,
  /// shear areas k·A (k = 6/7, Cowper's factor at ν = 0; DESIGN.md §8).
  static BeamSection circular(double E, double G, double R, double shear_factor = 6.0 / 7.0);
  /// Circular section of `law` (E, G, R) with elasto-plastic bending.
  static BeamSection circular_plastic(const PlasticBendingLaw& law, double shear_factor = 6.0 / 7.0);
  /// Section constants given directly (elastic beams, e.g. square benchmarks).
  static BeamSection from_values(double E, double G, double A, double A2, double A3, double I2, double I3,
                                 double IT);
  /// Throws InputError (naming `where`) unless every stiffness is positive and finite.
  void validate(const std::string& where) const;
};

}  // namespace stentsim::solver::beams
