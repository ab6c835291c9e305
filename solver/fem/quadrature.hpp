#pragma once
// Quadrature rules on the reference elements. Each element type picks the
// rule that integrates its linear-elastic stiffness (and, for surfaces, the
// follower-pressure and spring integrands) exactly on undistorted elements.
#include <array>
#include <cmath>

namespace stentsim::solver::fem {

template <int Dim, int N>
struct QuadratureRule {
  static constexpr int kPoints = N;
  std::array<std::array<double, Dim>, N> points;
  std::array<double, N> weights;
};

inline constexpr double kGauss2 = 0.57735026918962576451;  // 1/sqrt(3)

/// 2 x 2 x 2 Gauss on [-1,1]^3 (full integration of hex8, as the balloon calibration requires).
inline constexpr QuadratureRule<3, 8> gauss_hex_2x2x2() {
  QuadratureRule<3, 8> r{};
  int q = 0;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        r.points[q] = {i ? kGauss2 : -kGauss2, j ? kGauss2 : -kGauss2, k ? kGauss2 : -kGauss2};
        r.weights[q] = 1.0;
        ++q;
      }
  return r;
}

/// 2 x 2 Gauss on [-1,1]^2 (quad4: exact for pressure and spring integrands).
inline constexpr QuadratureRule<2, 4> gauss_quad_2x2() {
  QuadratureRule<2, 4> r{};
  int q = 0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      r.points[q] = {i ? kGauss2 : -kGauss2, j ? kGauss2 : -kGauss2};
      r.weights[q] = 1.0;
      ++q;
    }
  return r;
}

/// Centroid rule on the unit tetrahedron (tet4: constant gradients).
inline constexpr QuadratureRule<3, 1> tet_1point() { return {{{{0.25, 0.25, 0.25}}}, {1.0 / 6.0}}; }

/// 4-point degree-2 rule on the unit tetrahedron (tet10; Keast 1986 / Zienkiewicz).
inline constexpr QuadratureRule<3, 4> tet_4point() {
  constexpr double a = 0.58541019662496845446, b = 0.13819660112501051518;
  return {{{{b, b, b}, {a, b, b}, {b, a, b}, {b, b, a}}}, {1.0 / 24, 1.0 / 24, 1.0 / 24, 1.0 / 24}};
}

/// 3-point degree-2 rule on the unit triangle (tri3: exact for N_I N_J).
inline constexpr QuadratureRule<2, 3> tri_3point() {
  return {{{{1.0 / 6, 1.0 / 6}, {2.0 / 3, 1.0 / 6}, {1.0 / 6, 2.0 / 3}}}, {1.0 / 6, 1.0 / 6, 1.0 / 6}};
}

/// 6-point degree-4 rule on the unit triangle (tri6: exact for N_I N_J and the pressure integrand).
inline constexpr QuadratureRule<2, 6> tri_6point() {
  constexpr double a = 0.44594849091596488632, wa = 0.22338158967801146570 / 2;
  constexpr double b = 0.09157621350977074346, wb = 0.10995174365532186764 / 2;
  return {{{{a, a}, {1 - 2 * a, a}, {a, 1 - 2 * a}, {b, b}, {1 - 2 * b, b}, {b, 1 - 2 * b}}}, {wa, wa, wa, wb, wb, wb}};
}

}  // namespace stentsim::solver::fem
