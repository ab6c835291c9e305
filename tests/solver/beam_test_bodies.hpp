#pragma once
// Beam bodies for the tests: a curve given by its triad field, cut into
// equal elements. Node numbering: end nodes 0..N first (node N = tip), then
// the Hermite middle nodes N+1..2N.
#include "solver/beams/beam_term.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <numbers>

namespace stentsim::solver::beams::testing {

/// Position and triad (d1 = unit tangent) at arc length s.
using CurveFn = std::function<void(double s, Eigen::Vector3d& r, Eigen::Matrix3d& triad)>;

inline BeamBodyDefinition curve_body(const CurveFn& curve, double length, int n, const BeamSection& section,
                                     BeamInterpolation kind = BeamInterpolation::hermite3, int gauss_points = 0) {
  BeamBodyDefinition b;
  b.interpolation = kind;
  b.section = section;
  b.gauss_points = gauss_points;
  auto node = [&](double s) {
    BeamNode nd;
    Eigen::Matrix3d T;
    curve(s, nd.position, T);
    nd.triad = Eigen::Quaterniond(T);
    return nd;
  };
  for (int i = 0; i <= n; ++i) b.nodes.push_back(node(length * i / n));
  for (int e = 0; e < n; ++e) {
    BeamElement el{e, e + 1, -1};
    if (kind == BeamInterpolation::hermite3) {
      el.mid = static_cast<int>(b.nodes.size());
      b.nodes.push_back(node(length * (e + 0.5) / n));
    }
    b.elements.push_back(el);
  }
  return b;
}

/// Straight beam along +x from the origin, triad = identity.
inline CurveFn straight_x() {
  return [](double s, Eigen::Vector3d& r, Eigen::Matrix3d& T) {
    r = Eigen::Vector3d(s, 0, 0);
    T.setIdentity();
  };
}

/// The Bathe–Bolourchi 45° bend: arc of radius R in the x–y plane, centre
/// (R, 0, 0), starting at the origin with tangent +y; d3 = e_z.
inline CurveFn arc_xy(double R) {
  return [R](double s, Eigen::Vector3d& r, Eigen::Matrix3d& T) {
    const double p = s / R;
    r = Eigen::Vector3d(R - R * std::cos(p), R * std::sin(p), 0.0);
    const Eigen::Vector3d d1(std::sin(p), std::cos(p), 0.0), d3(0, 0, 1);
    T.col(0) = d1;
    T.col(1) = d3.cross(d1);
    T.col(2) = d3;
  };
}

/// A twisted 3D curve (helix) whose triad also twists: a generic reference.
inline CurveFn helix(double radius, double pitch) {
  return [=](double s, Eigen::Vector3d& r, Eigen::Matrix3d& T) {
    const double c = std::sqrt(radius * radius + pitch * pitch);
    const double p = s / c;
    r = Eigen::Vector3d(radius * std::cos(p), radius * std::sin(p), pitch * p);
    const Eigen::Vector3d d1 = Eigen::Vector3d(-radius * std::sin(p), radius * std::cos(p), pitch) / c;
    Eigen::Vector3d n(-std::cos(p), -std::sin(p), 0.0);
    const double tw = 0.3 * s;  // extra twist of the section about d1
    const Eigen::Vector3d b = d1.cross(n);
    T.col(0) = d1;
    T.col(1) = std::cos(tw) * n + std::sin(tw) * b;
    T.col(2) = d1.cross(T.col(1));
  };
}

}  // namespace stentsim::solver::beams::testing
