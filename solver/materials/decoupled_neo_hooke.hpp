#pragma once
// Decoupled compressible neo-Hooke, the matrix of svMultiPhysics's HGO
// (Holzapfel, Gasser & Ogden 2000, with the Simo-Taylor 1991 volumetric term):
//   Psi = mu/2 (Ibar1 - 3) + K/4 (J^2 - 1 - 2 ln J),  Ibar1 = J^(-2/3) I1.
// Volumetric part (U' = K/2 (J - 1/J), U'' = K/2 (1 + 1/J^2)):
//   S_vol  = J U' C^-1 = K/2 (J^2 - 1) C^-1
//   CC_vol = J (U' + J U'') C^-1 (x) C^-1 - 2 J U' C^-1 (.) C^-1
//          = K J^2 C^-1 (x) C^-1 - K (J^2 - 1) C^-1 (.) C^-1.
// The isochoric part: isochoric_invariant.hpp with A = 1, psi' = mu/2.
#include "solver/fem/tensor.hpp"
#include "solver/materials/point_status.hpp"

namespace stentsim::solver {

struct DecoupledNeoHooke {
  double mu = 0.0;     // shear modulus, MPa
  double kappa = 0.0;  // bulk modulus, MPa

  /// mu = E / (2 (1 + nu)), K = E / (3 (1 - 2 nu)), as svMultiPhysics derives them.
  static DecoupledNeoHooke from_young_poisson(double young, double poisson) {
    return {young / (2.0 * (1.0 + poisson)), young / (3.0 * (1.0 - 2.0 * poisson))};
  }

  double energy(const Mat3& cauchy_green, double j) const;
  /// Adds S (Voigt) and, when `tangent` is not null, dS/dE (Voigt).
  PointStatus add(const Mat3& cauchy_green, const Mat3& c_inv, double j, Vec6& stress, Mat6* tangent) const;
};

}  // namespace stentsim::solver
