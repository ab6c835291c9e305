#include "solver/materials/material.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace stentsim::solver {

PointStatus Material::elastic(const Mat3& cauchy_green, const Vec3* fiber_dirs, Vec6& stress, Mat6* tangent) const {
  stress.setZero();
  if (tangent) tangent->setZero();
  // C^-1 and J once per point, for every summand that needs them.
  const bool kinematics = matrix || decoupled_matrix ||
                          std::any_of(fibers.begin(), fibers.end(), [](const FiberFamilySpec& f) { return f.law.isochoric; });
  Mat3 c_inv = Mat3::Identity();
  double j = 1.0;
  if (kinematics) {
    const double j2 = cauchy_green.determinant();
    if (!(j2 > 0.0)) return PointStatus::fail("det C <= 0 (inverted element)");
    c_inv = cauchy_green.inverse();
    j = std::sqrt(j2);
  }
  if (matrix)
    if (auto s = matrix->add(cauchy_green, c_inv, j, stress, tangent); !s.ok) return s;
  if (decoupled_matrix)
    if (auto s = decoupled_matrix->add(cauchy_green, c_inv, j, stress, tangent); !s.ok) return s;
  for (std::size_t f = 0; f < fibers.size(); ++f)
    if (auto s = fibers[f].law.add(cauchy_green, c_inv, j, fiber_dirs[f], stress, tangent); !s.ok) return s;
  if (!stress.allFinite()) return PointStatus::fail("stress is not finite");
  return PointStatus::good();
}

double Material::energy(const Mat3& cauchy_green, const Vec3* fiber_dirs) const {
  double w = 0.0;
  if (matrix) w += matrix->energy(cauchy_green, std::sqrt(cauchy_green.determinant()));
  if (decoupled_matrix) w += decoupled_matrix->energy(cauchy_green, std::sqrt(cauchy_green.determinant()));
  for (std::size_t f = 0; f < fibers.size(); ++f) w += fibers[f].law.energy(cauchy_green, fiber_dirs[f]);
  return w;
}

std::string Material::describe() const {
  std::string s = name + ":";
  if (matrix)
    s += fmt::format(" coupled neo-Hooke c={:g} MPa beta={:g} (G={:g} MPa);", matrix->c, matrix->beta,
                     matrix->shear_modulus());
  if (decoupled_matrix)
    s += fmt::format(" decoupled neo-Hooke mu={:g} MPa K={:g} MPa;", decoupled_matrix->mu, decoupled_matrix->kappa);
  for (const auto& f : fibers) {
    s += fmt::format(" fibers{} k1={:g} MPa k2={:g}", f.law.isochoric ? " on Ibar4" : "", f.law.k1, f.law.k2);
    if (f.global_direction) s += fmt::format(" dir=({:g},{:g},{:g})", (*f.global_direction)(0), (*f.global_direction)(1), (*f.global_direction)(2));
    else s += fmt::format(" angle={:g} deg", f.angle_deg);
    s += f.law.tension_only ? " tension-only;" : ";";
  }
  if (viscous) s += fmt::format(" viscous tau={:g} s beta={:g};", viscous->tau, viscous->beta);
  return s;
}

}  // namespace stentsim::solver
