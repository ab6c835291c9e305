#include "solver/materials/coupled_neo_hooke.hpp"

#include <cmath>

namespace stentsim::solver {
namespace {
// exp() of more than this overflows double range well before Inf; reported instead.
constexpr double kMaxExponent = 600.0;
}

double CoupledNeoHooke::energy(const Mat3& cauchy_green, double j) const {
  const double i1 = cauchy_green.trace();
  if (beta == 0.0) return c * (i1 - 3.0) - 2.0 * c * std::log(j);
  return c * (i1 - 3.0) + c / beta * (std::exp(-2.0 * beta * std::log(j)) - 1.0);
}

PointStatus CoupledNeoHooke::add(const Mat3& cauchy_green, const Mat3& c_inv, double j, Vec6& stress,
                                 Mat6* tangent) const {
  if (!(j > 0.0)) return PointStatus::fail("J <= 0 (inverted element)");
  const double exponent = -2.0 * beta * std::log(j);
  if (exponent > kMaxExponent) return PointStatus::fail("J^(-2 beta) overflows (J near 0)");
  const double jpow = std::exp(exponent);
  stress += 2.0 * c * (to_voigt_stress(Mat3::Identity()) - jpow * to_voigt_stress(c_inv));
  if (tangent) {
    add_outer(*tangent, 4.0 * c * beta * jpow, c_inv, c_inv);
    add_symmetric_product(*tangent, 4.0 * c * jpow, c_inv, c_inv);
  }
  return PointStatus::good();
}

}  // namespace stentsim::solver
