#pragma once
// One exponential fiber family (Holzapfel-Gasser-Ogden; paper App. B):
//   Psi = k1 / (2 k2) (exp(k2 (I4 - 1)^2) - 1),  I4 = M . C M.
// S  = 2 Psi' M (x) M,            Psi'  = k1 (I4 - 1) exp(k2 (I4 - 1)^2)
// CC = 4 Psi'' M (x) M (x) M (x) M, Psi'' = k1 exp(k2 (I4 - 1)^2) (1 + 2 k2 (I4 - 1)^2)
// `tension_only`: no contribution while I4 < 1 (fibers do not carry
// compression; DESIGN.md §8 keeps the paper's both-ways form as default).
// `multiplicity` counts coinciding families (two families at 0 deg count twice).
// `isochoric`: the family acts on Ibar4 = J^(-2/3) I4 instead (the decoupled
// HGO of svMultiPhysics; stress and tangent by isochoric_invariant.hpp).
#include "solver/fem/tensor.hpp"
#include "solver/materials/point_status.hpp"

namespace stentsim::solver {

struct FiberFamily {
  double k1 = 0.0;  // MPa
  double k2 = 0.0;  // dimensionless
  bool tension_only = false;
  double multiplicity = 1.0;
  bool isochoric = false;

  double energy(const Mat3& cauchy_green, const Vec3& m) const;
  /// Adds S and dS/dE (when `tangent` is not null) for the unit reference direction `m`;
  /// `c_inv` and `j` (C^-1 and J, computed once per point by the material) serve `isochoric`.
  PointStatus add(const Mat3& cauchy_green, const Mat3& c_inv, double j, const Vec3& m, Vec6& stress, Mat6* tangent) const;
};

}  // namespace stentsim::solver
