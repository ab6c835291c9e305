#include "solver/materials/decoupled_neo_hooke.hpp"

#include <cmath>

#include "solver/materials/isochoric_invariant.hpp"

namespace stentsim::solver {

double DecoupledNeoHooke::energy(const Mat3& cauchy_green, double j) const {
  const double i1bar = isochoric_invariant(Mat3::Identity(), cauchy_green, j);
  return 0.5 * mu * (i1bar - 3.0) + 0.25 * kappa * (j * j - 1.0 - 2.0 * std::log(j));
}

PointStatus DecoupledNeoHooke::add(const Mat3& cauchy_green, const Mat3& c_inv, double j, Vec6& stress,
                                   Mat6* tangent) const {
  if (!(j > 0.0)) return PointStatus::fail("J <= 0 (inverted element)");
  add_isochoric_invariant(Mat3::Identity(), cauchy_green, c_inv, j, 0.5 * mu, 0.0, stress, tangent);
  stress += 0.5 * kappa * (j * j - 1.0) * to_voigt_stress(c_inv);
  if (tangent) {
    add_outer(*tangent, kappa * j * j, c_inv, c_inv);
    add_symmetric_product(*tangent, -kappa * (j * j - 1.0), c_inv, c_inv);
  }
  return PointStatus::good();
}

}  // namespace stentsim::solver
