#pragma once
// Reference elements: shape functions and their reference gradients, node
// order as VTK (vtkCellType.h), and the quadrature each one uses. Volume
// elements (hex8, tet4, tet10) carry the solid; surface elements (quad4,
// tri3, tri6) carry pressures and springs. All sizes are compile-time so the
// element kernels run on fixed-size Eigen matrices without allocation.
#include <Eigen/Core>

#include <array>

#include "common/mesh_data.hpp"
#include "solver/fem/quadrature.hpp"

namespace stentsim::solver::fem {

template <int N, int Dim>
struct ShapeValues {
  Eigen::Matrix<double, N, 1> n;
  Eigen::Matrix<double, N, Dim> dn;  // dN_I / dxi_k
};

struct Hex8 {
  static constexpr int kNodes = 8, kDim = 3;
  static constexpr CellType kCell = CellType::hexahedron;
  static constexpr const char* kName = "hex8";
  static constexpr std::array<std::array<double, 3>, 8> kNodeXi{
      {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}}};
  static constexpr auto kRule = gauss_hex_2x2x2();
  static ShapeValues<8, 3> eval(const std::array<double, 3>& xi) {
    ShapeValues<8, 3> s;
    for (int i = 0; i < 8; ++i) {
      const double a = 1 + xi[0] * kNodeXi[i][0], b = 1 + xi[1] * kNodeXi[i][1], c = 1 + xi[2] * kNodeXi[i][2];
      s.n(i) = 0.125 * a * b * c;
      s.dn(i, 0) = 0.125 * kNodeXi[i][0] * b * c;
      s.dn(i, 1) = 0.125 * a * kNodeXi[i][1] * c;
      s.dn(i, 2) = 0.125 * a * b * kNodeXi[i][2];
    }
    return s;
  }
};

struct Quad4 {
  static constexpr int kNodes = 4, kDim = 2;
  static constexpr CellType kCell = CellType::quad;
  static constexpr const char* kName = "quad4";
  static constexpr std::array<std::array<double, 2>, 4> kNodeXi{{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}};
  static constexpr auto kRule = gauss_quad_2x2();
  static ShapeValues<4, 2> eval(const std::array<double, 2>& xi) {
    ShapeValues<4, 2> s;
    for (int i = 0; i < 4; ++i) {
      const double a = 1 + xi[0] * kNodeXi[i][0], b = 1 + xi[1] * kNodeXi[i][1];
      s.n(i) = 0.25 * a * b;
      s.dn(i, 0) = 0.25 * kNodeXi[i][0] * b;
      s.dn(i, 1) = 0.25 * a * kNodeXi[i][1];
    }
    return s;
  }
};

namespace detail {
/// Barycentric coordinates of a point of the unit simplex: L0 = 1 - sum(xi), L_k = xi_{k-1}.
template <int Dim>
inline std::array<double, Dim + 1> barycentric(const std::array<double, Dim>& xi) {
  std::array<double, Dim + 1> l{};
  l[0] = 1.0;
  for (int k = 0; k < Dim; ++k) {
    l[k + 1] = xi[k];
    l[0] -= xi[k];
  }
  return l;
}
/// dL_a / dxi_k.
inline constexpr double dbary(int a, int k) { return a == 0 ? -1.0 : (a == k + 1 ? 1.0 : 0.0); }

/// Linear simplex (tri3, tet4): N_a = L_a.
template <int Dim>
inline ShapeValues<Dim + 1, Dim> linear_simplex(const std::array<double, Dim>& xi) {
  ShapeValues<Dim + 1, Dim> s;
  const auto l = barycentric<Dim>(xi);
  for (int a = 0; a <= Dim; ++a) {
    s.n(a) = l[a];
    for (int k = 0; k < Dim; ++k) s.dn(a, k) = dbary(a, k);
  }
  return s;
}

/// Quadratic simplex (tri6, tet10): corners L(2L-1), edge nodes 4 L_a L_b.
template <int Dim, int N>
inline ShapeValues<N, Dim> quadratic_simplex(const std::array<double, Dim>& xi,
                                             const std::array<std::array<int, 2>, N - Dim - 1>& edges) {
  ShapeValues<N, Dim> s;
  const auto l = barycentric<Dim>(xi);
  for (int a = 0; a <= Dim; ++a) {
    s.n(a) = l[a] * (2 * l[a] - 1);
    for (int k = 0; k < Dim; ++k) s.dn(a, k) = (4 * l[a] - 1) * dbary(a, k);
  }
  for (int e = 0; e < N - Dim - 1; ++e) {
    const int a = edges[e][0], b = edges[e][1];
    s.n(Dim + 1 + e) = 4 * l[a] * l[b];
    for (int k = 0; k < Dim; ++k) s.dn(Dim + 1 + e, k) = 4 * (dbary(a, k) * l[b] + l[a] * dbary(b, k));
  }
  return s;
}
}  // namespace detail

struct Tet4 {
  static constexpr int kNodes = 4, kDim = 3;
  static constexpr CellType kCell = CellType::tetra;
  static constexpr const char* kName = "tet4";
  static constexpr auto kRule = tet_1point();
  static ShapeValues<4, 3> eval(const std::array<double, 3>& xi) { return detail::linear_simplex<3>(xi); }
};

struct Tet10 {
  static constexpr int kNodes = 10, kDim = 3;
  static constexpr CellType kCell = CellType::quadratic_tetra;
  static constexpr const char* kName = "tet10";
  static constexpr std::array<std::array<int, 2>, 6> kEdges{{{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}}};
  static constexpr auto kRule = tet_4point();
  // Curved edges let J = det F change sign between the Gauss points and the
  // corners: the solid kernel checks it at these points too (DESIGN.md §7).
  static constexpr std::array<std::array<double, 3>, 4> kCornerXi{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  static ShapeValues<10, 3> eval(const std::array<double, 3>& xi) { return detail::quadratic_simplex<3, 10>(xi, kEdges); }
};

struct Tri3 {
  static constexpr int kNodes = 3, kDim = 2;
  static constexpr CellType kCell = CellType::triangle;
  static constexpr const char* kName = "tri3";
  static constexpr auto kRule = tri_3point();
  static ShapeValues<3, 2> eval(const std::array<double, 2>& xi) { return detail::linear_simplex<2>(xi); }
};

struct Tri6 {
  static constexpr int kNodes = 6, kDim = 2;
  static constexpr CellType kCell = CellType::quadratic_triangle;
  static constexpr const char* kName = "tri6";
  static constexpr std::array<std::array<int, 2>, 3> kEdges{{{0, 1}, {1, 2}, {2, 0}}};
  static constexpr auto kRule = tri_6point();
  static ShapeValues<6, 2> eval(const std::array<double, 2>& xi) { return detail::quadratic_simplex<2, 6>(xi, kEdges); }
};

}  // namespace stentsim::solver::fem
