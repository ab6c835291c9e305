#pragma once
// Shape functions of the contact surface faces (quad4, tri3, tri6; VTK node
// order, as fem/elements.hpp) with first and second parametric derivatives.
// The projections need the second derivatives: the gap's Hessian contains the
// surface curvature x,ab (normal_projection.hpp).
#include <Eigen/Core>

#include <array>
#include <stdexcept>

#include "common/mesh_data.hpp"

namespace stentsim::solver::contact {

enum class FaceKind { quad4, tri3, tri6 };

inline int face_nodes(FaceKind k) { return k == FaceKind::quad4 ? 4 : k == FaceKind::tri3 ? 3 : 6; }
inline const char* face_kind_name(FaceKind k) { return k == FaceKind::quad4 ? "quad4" : k == FaceKind::tri3 ? "tri3" : "tri6"; }
inline FaceKind face_kind(CellType t) {
  switch (t) {
    case CellType::quad: return FaceKind::quad4;
    case CellType::triangle: return FaceKind::tri3;
    case CellType::quadratic_triangle: return FaceKind::tri6;
    default: throw std::invalid_argument("contact surfaces take quad4, tri3 and tri6 faces");
  }
}

struct FaceShape {
  std::array<double, 6> n{};
  std::array<std::array<double, 2>, 6> dn{};      // dN/dξ_a
  std::array<std::array<double, 3>, 6> ddn{};     // d²N/dξ1², d²N/dξ1dξ2, d²N/dξ2²
};

/// Parametric coordinates of node i.
inline std::array<double, 2> face_node_xi(FaceKind k, int i) {
  static constexpr double q[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  static constexpr double t[6][2] = {{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}};
  if (k == FaceKind::quad4) return {q[i][0], q[i][1]};
  return {t[i][0], t[i][1]};
}

/// The face's centre (start of the projection's Newton iteration).
inline std::array<double, 2> face_center(FaceKind k) {
  return k == FaceKind::quad4 ? std::array<double, 2>{0.0, 0.0} : std::array<double, 2>{1.0 / 3.0, 1.0 / 3.0};
}

/// Is (ξ1, ξ2) inside the reference face, up to `tol`?
inline bool inside_face(FaceKind k, double x1, double x2, double tol) {
  if (k == FaceKind::quad4) return x1 >= -1 - tol && x1 <= 1 + tol && x2 >= -1 - tol && x2 <= 1 + tol;
  return x1 >= -tol && x2 >= -tol && x1 + x2 <= 1 + tol;
}

inline FaceShape face_shape(FaceKind k, double x1, double x2) {
  FaceShape s;
  if (k == FaceKind::quad4) {
    for (int i = 0; i < 4; ++i) {
      const auto c = face_node_xi(k, i);
      const double a = 1 + c[0] * x1, b = 1 + c[1] * x2;
      s.n[i] = 0.25 * a * b;
      s.dn[i] = {0.25 * c[0] * b, 0.25 * a * c[1]};
      s.ddn[i] = {0.0, 0.25 * c[0] * c[1], 0.0};
    }
    return s;
  }
  // Barycentric L0 = 1 − ξ1 − ξ2, L1 = ξ1, L2 = ξ2; dL/dξ = {(−1,−1), (1,0), (0,1)}.
  const double l[3] = {1 - x1 - x2, x1, x2};
  static constexpr double dl[3][2] = {{-1, -1}, {1, 0}, {0, 1}};
  if (k == FaceKind::tri3) {
    for (int i = 0; i < 3; ++i) s.n[i] = l[i], s.dn[i] = {dl[i][0], dl[i][1]}, s.ddn[i] = {0, 0, 0};
    return s;
  }
  // tri6: corners L(2L − 1), midsides 4 L_i L_j on edges (0,1), (1,2), (2,0).
  for (int i = 0; i < 3; ++i) {
    s.n[i] = l[i] * (2 * l[i] - 1);
    for (int a = 0; a < 2; ++a) s.dn[i][a] = (4 * l[i] - 1) * dl[i][a];
    s.ddn[i] = {4 * dl[i][0] * dl[i][0], 4 * dl[i][0] * dl[i][1], 4 * dl[i][1] * dl[i][1]};
  }
  static constexpr int e[3][2] = {{0, 1}, {1, 2}, {2, 0}};
  for (int m = 0; m < 3; ++m) {
    const int i = e[m][0], j = e[m][1];
    s.n[3 + m] = 4 * l[i] * l[j];
    for (int a = 0; a < 2; ++a) s.dn[3 + m][a] = 4 * (dl[i][a] * l[j] + l[i] * dl[j][a]);
    s.ddn[3 + m] = {8 * dl[i][0] * dl[j][0], 4 * (dl[i][0] * dl[j][1] + dl[i][1] * dl[j][0]), 8 * dl[i][1] * dl[j][1]};
  }
  return s;
}

}  // namespace stentsim::solver::contact
