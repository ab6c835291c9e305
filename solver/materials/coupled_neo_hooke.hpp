#pragma once
// Coupled compressible neo-Hooke (4C CoupNeoHooke; DESIGN.md §5):
//   Psi = c (I1 - 3) + (c / beta) (J^(-2 beta) - 1),  c = E / (4 (1 + nu)),  beta = nu / (1 - 2 nu).
// nu = 0 gives beta = 0 and the limit Psi = c (I1 - 3) - 2 c ln J.
// S = 2 dPsi/dC = 2c (I - J^(-2beta) C^-1)  (the same formula covers beta = 0)
// CC = 2 dS/dC = 4 c beta J^(-2beta) C^-1 (x) C^-1 + 4 c J^(-2beta) (C^-1 (.) C^-1).
// J^(-2beta) is evaluated as exp(-2 beta ln J) with an overflow guard.
#include "solver/fem/tensor.hpp"
#include "solver/materials/point_status.hpp"

namespace stentsim::solver {

struct CoupledNeoHooke {
  double c = 0.0;     // MPa
  double beta = 0.0;  // dimensionless

  static CoupledNeoHooke from_young_poisson(double young, double poisson) {
    return {young / (4.0 * (1.0 + poisson)), poisson / (1.0 - 2.0 * poisson)};
  }
  double shear_modulus() const { return 2.0 * c; }

  /// Strain energy per reference volume (for checks and output).
  double energy(const Mat3& cauchy_green, double j) const;
  /// Adds S (Voigt) and, when `tangent` is not null, dS/dE (Voigt).
  PointStatus add(const Mat3& cauchy_green, const Mat3& c_inv, double j, Vec6& stress, Mat6* tangent) const;
};

}  // namespace stentsim::solver
