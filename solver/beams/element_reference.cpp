#include "solver/beams/element_reference.hpp"

#include "solver/beams/beam_kernel.hpp"

#include "common/error.hpp"

#include <cmath>
#include <numbers>

namespace stentsim::solver::beams {

void gauss_legendre(int n, std::vector<double>& points, std::vector<double>& weights) {
  // Newton on the Legendre polynomial P_n from Chebyshev guesses.
  points.assign(n, 0.0);
  weights.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      const double pn = n == 0 ? 1.0 : p1;
      dp = n * (x * pn - p0) / (x * x - 1.0);
      const double dx = pn / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    // recompute derivative at the converged root
    double p0 = 1.0, p1 = x;
    for (int k = 2; k <= n; ++k) {
      const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    dp = n * (x * p1 - p0) / (x * x - 1.0);
    points[n - 1 - i] = x;
    weights[n - 1 - i] = 2.0 / ((1.0 - x * x) * dp * dp);
  }
}

namespace {

// Hermite functions on [−1, 1] and their ξ-derivatives (tangent ones unscaled).
void hermite(double xi, std::array<double, 4>& H, std::array<double, 4>& dH) {
  H = {(2.0 - 3.0 * xi + xi * xi * xi) / 4.0, (1.0 - xi - xi * xi + xi * xi * xi) / 4.0,
       (2.0 + 3.0 * xi - xi * xi * xi) / 4.0, (-1.0 - xi + xi * xi + xi * xi * xi) / 4.0};
  dH = {(-3.0 + 3.0 * xi * xi) / 4.0, (-1.0 - 2.0 * xi + 3.0 * xi * xi) / 4.0, (3.0 - 3.0 * xi * xi) / 4.0,
        (-1.0 + 2.0 * xi + 3.0 * xi * xi) / 4.0};
}

// Centerline functions with the tangent scaling l/2, and their ξ-derivatives.
void centerline_functions(BeamInterpolation kind, double l, double xi, std::array<double, 4>& B,
                          std::array<double, 4>& dBdxi) {
  if (kind == BeamInterpolation::hermite3) {
    hermite(xi, B, dBdxi);
    for (int k : {1, 3}) {
      B[k] *= 0.5 * l;
      dBdxi[k] *= 0.5 * l;
    }
  } else {
    B = {0.5 * (1.0 - xi), 0.5 * (1.0 + xi), 0.0, 0.0};
    dBdxi = {-0.5, 0.5, 0.0, 0.0};
  }
}

double jacobian(const ElementReference& r, double l, double xi) {
  std::array<double, 4> B, dB;
  centerline_functions(r.kind, l, xi, B, dB);
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  for (int k = 0; k < r.centerline_vectors(); ++k) d += dB[k] * r.x0[k];
  return d.norm();
}

}  // namespace

ShapePoint ElementReference::at(double xi) const {
  ShapePoint p;
  p.xi = xi;
  std::array<double, 4> dBdxi;
  centerline_functions(kind, length, xi, p.B, dBdxi);
  const double J = jacobian(*this, length, xi);
  for (int k = 0; k < 4; ++k) p.dB[k] = dBdxi[k] / J;
  if (kind == BeamInterpolation::hermite3) {
    // nodes a (ξ = −1), b (ξ = +1), mid (ξ = 0)
    p.N = {0.5 * xi * (xi - 1.0), 0.5 * xi * (xi + 1.0), 1.0 - xi * xi};
    p.dN = {(xi - 0.5) / J, (xi + 0.5) / J, -2.0 * xi / J};
  } else {
    p.N = {0.5 * (1.0 - xi), 0.5 * (1.0 + xi), 0.0};
    p.dN = {-0.5 / J, 0.5 / J, 0.0};
  }
  // Reference strains: evaluate the state at the reference with zero offsets.
  ShapePoint raw = p;
  raw.Gamma0.setZero();
  raw.Kappa0.setZero();
  const BeamSection unit = BeamSection::from_values(1, 1, 1, 1, 1, 1, 1, 1);
  const SectionState s = kind == BeamInterpolation::hermite3 ? section_state<4, 3>(raw, unit, x0, q0)
                                                             : section_state<2, 2>(raw, unit, x0, q0);
  p.Gamma0 = s.Gamma;
  p.Kappa0 = s.Omega;
  return p;
}

ElementReference make_element_reference(BeamInterpolation kind, const std::array<Eigen::Vector3d, 4>& x0,
                                        const std::array<Eigen::Quaterniond, 3>& q0, int gauss_points) {
  ElementReference r;
  r.kind = kind;
  r.x0 = x0;
  r.q0 = q0;
  for (auto& q : r.q0) q.normalize();
  if (kind == BeamInterpolation::hermite3) {
    // l = ∫ |∂r₀/∂ξ| dξ depends on l through the tangent scaling: fixed point.
    std::vector<double> xs, ws;
    gauss_legendre(20, xs, ws);
    double l = (x0[2] - x0[0]).norm();
    if (!(l > 0.0)) throw InputError("beam element: end nodes coincide (zero length)");
    for (int it = 0; it < 200; ++it) {
      double ln = 0.0;
      for (std::size_t i = 0; i < xs.size(); ++i) ln += ws[i] * jacobian(r, l, xs[i]);
      const bool done = std::abs(ln - l) <= 1e-15 * l;
      l = ln;
      if (done) break;
    }
    r.length = l;
  } else {
    r.length = (x0[1] - x0[0]).norm();
    if (!(r.length > 0.0)) throw InputError("beam element: end nodes coincide (zero length)");
  }
  const int ngp = gauss_points > 0 ? gauss_points : (kind == BeamInterpolation::hermite3 ? 3 : 1);
  std::vector<double> xs, ws;
  gauss_legendre(ngp, xs, ws);
  for (int i = 0; i < ngp; ++i) {
    ShapePoint p = r.at(xs[i]);
    p.weight_ds = ws[i] * jacobian(r, r.length, xs[i]);
    r.points.push_back(p);
  }
  return r;
}

}  // namespace stentsim::solver::beams
