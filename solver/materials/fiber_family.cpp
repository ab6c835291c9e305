#include "solver/materials/fiber_family.hpp"

#include <cmath>

#include "solver/materials/isochoric_invariant.hpp"

namespace stentsim::solver {
namespace {
constexpr double kMaxExponent = 600.0;
}

double FiberFamily::energy(const Mat3& cauchy_green, const Vec3& m) const {
  const double i4 = m.dot(cauchy_green * m);
  const double e = (isochoric ? std::pow(cauchy_green.determinant(), -1.0 / 3.0) * i4 : i4) - 1.0;
  if (tension_only && e < 0.0) return 0.0;
  if (k2 == 0.0) return multiplicity * 0.5 * k1 * e * e;
  return multiplicity * k1 / (2.0 * k2) * (std::exp(k2 * e * e) - 1.0);
}

PointStatus FiberFamily::add(const Mat3& cauchy_green, const Mat3& c_inv, double j, const Vec3& m, Vec6& stress,
                             Mat6* tangent) const {
  const double i4 = m.dot(cauchy_green * m);
  const double e = (isochoric ? std::pow(j, -2.0 / 3.0) * i4 : i4) - 1.0;  // I4 - 1 or Ibar4 - 1
  if (tension_only && e < 0.0) return PointStatus::good();
  const double exponent = k2 * e * e;
  if (exponent > kMaxExponent) return PointStatus::fail("fiber exponential overflows (I4 too large)");
  const double ex = std::exp(exponent);
  const double d1 = multiplicity * k1 * e * ex;
  const double d2 = multiplicity * k1 * ex * (1.0 + 2.0 * k2 * e * e);
  const Mat3 mm = m * m.transpose();
  if (isochoric) {
    add_isochoric_invariant(mm, cauchy_green, c_inv, j, d1, d2, stress, tangent);
    return PointStatus::good();
  }
  stress += 2.0 * d1 * to_voigt_stress(mm);
  if (tangent) add_outer(*tangent, 4.0 * d2, mm, mm);
  return PointStatus::good();
}

}  // namespace stentsim::solver
