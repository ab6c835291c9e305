#pragma once
// Analytic mesher inputs for the patient-mesh tests: triangulated tube
// surfaces and centerlines (with ParallelTransportNormals) of a straight tube
// along z and of a circular bend in the x-z plane.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "common/mesh_data.hpp"

namespace stentsim::test {

/// A tube of radius r around the curve c(u), u in [0, 1], with the unit
/// vectors e1(u), e2(u) spanning its normal plane; nt around, nz along.
template <class C, class E1, class E2>
MeshData swept_tube(double r, C c, E1 e1, E2 e2, int nt, int nz) {
  MeshData m;
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i < nt; ++i) {
      const double u = double(j) / nz, th = 2 * std::numbers::pi * i / nt;
      m.points.push_back(c(u) + r * (std::cos(th) * e1(u) + std::sin(th) * e2(u)));
    }
  auto id = [&](int i, int j) { return std::int64_t(j * nt + (i % nt)); };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nt; ++i) {
      m.add_cell(CellType::triangle, {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.add_cell(CellType::triangle, {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

template <class C, class N>
MeshData swept_centerline(C c, N normal, int n, bool with_normals = true) {
  MeshData m;
  DataArray ptn{3, {}};
  std::vector<std::int64_t> ids;
  for (int j = 0; j < n; ++j) {
    const double u = double(j) / (n - 1);
    m.points.push_back(c(u));
    const Eigen::Vector3d v = normal(u);
    ptn.values.insert(ptn.values.end(), {v.x(), v.y(), v.z()});
    ids.push_back(j);
  }
  m.add_cell(CellType::polyline, ids);
  if (with_normals) m.point_data["ParallelTransportNormals"] = ptn;
  return m;
}

/// Straight tube along z, length `len`.
inline MeshData straight_tube(double r, double len, int nt = 96, int nz = 40) {
  return swept_tube(
      r, [len](double u) { return Eigen::Vector3d(0, 0, len * u); }, [](double) { return Eigen::Vector3d(1, 0, 0); },
      [](double) { return Eigen::Vector3d(0, 1, 0); }, nt, nz);
}
inline MeshData straight_centerline(double len, bool with_normals = true) {
  return swept_centerline([len](double u) { return Eigen::Vector3d(0, 0, len * u); },
                          [](double) { return Eigen::Vector3d(1, 0, 0); }, 41, with_normals);
}

/// Straight `a` mm along +z, a circular bend of radius `bend` turning by
/// `angle` towards +x, straight `b` mm; parametrized by arc length.
struct BentPath {
  double a, bend, angle, b;
  double length() const { return a + bend * angle + b; }
  Eigen::Vector3d c(double u) const {
    const double s = u * length();
    if (s <= a) return {0, 0, s};
    const double p = std::min(angle, (s - a) / bend);
    const Eigen::Vector3d end(bend * (1 - std::cos(p)), 0, a + bend * std::sin(p));
    return end + std::max(0.0, s - a - bend * angle) * t(u);
  }
  Eigen::Vector3d t(double u) const {
    const double p = std::clamp((u * length() - a) / bend, 0.0, angle);
    return {std::sin(p), 0, std::cos(p)};
  }
  Eigen::Vector3d e1(double u) const { return Eigen::Vector3d(0, 1, 0).cross(t(u)); }
};
inline MeshData path_tube(const BentPath& p, double r, int nt = 96, int nz = 120) {
  return swept_tube(
      r, [p](double u) { return p.c(u); }, [p](double u) { return p.e1(u); },
      [](double) { return Eigen::Vector3d(0, 1, 0); }, nt, nz);
}
inline MeshData path_centerline(const BentPath& p, int n = 121) {
  return swept_centerline([p](double u) { return p.c(u); }, [](double) { return Eigen::Vector3d(0, 1, 0); }, n);
}

}  // namespace stentsim::test
