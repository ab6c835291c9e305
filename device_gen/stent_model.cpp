#include "device_gen/stent_model.hpp"

#include <Eigen/Geometry>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include "common/error.hpp"

namespace stentsim::device_gen {
namespace {

/// A member in the unrolled plane: from (phi0, z0) to (phi1, z1).
struct Segment {
  double phi0, z0, phi1, z1;
};

}  // namespace

int StentModel::nodal_dofs() const {
  int dofs = 0;
  for (int k : node_kind) dofs += k == kEndNode ? 9 : 3;
  return dofs;
}

StentModel build_stent(const StentDesign& d, const DeviceAxis& axis) {
  StentModel s;
  s.length = d.length();
  if (s.length > axis.length() + 1e-12)
    throw InputError(fmt::format("stent: the stent ({} rings, {:.4g} mm) is longer than the balloon ({:.4g} mm)", d.rings,
                                 s.length, axis.length()));
  s.axis_start = 0.5 * (axis.length() - s.length);
  const double R = 0.5 * d.crimped_diameter;
  const int npr = 2 * d.crowns;  // crown points (and struts) per ring
  const double dphi = 2.0 * std::numbers::pi / npr;
  // Crown point k of ring r: valleys (even k) at the ring start, peaks (odd k)
  // one crown height further; all rings in phase. The angle is computed from
  // k mod npr so that coincident points are bitwise equal.
  auto crown = [&](int r, int k) -> std::pair<double, double> {
    const int kk = ((k % npr) + npr) % npr;
    return {kk * dphi, r * d.ring_pitch + (kk % 2 == 1 ? d.crown_height : 0.0)};
  };

  // Joint bookkeeping: end nodes that sit on the same crown point.
  std::map<std::pair<int, int>, std::vector<int>> at_point;  // (ring-level, crown index) -> nodes

  auto add_member = [&](StentModel::MemberKind kind, int ring, const Segment& seg, int n_el,
                        std::pair<int, int> key0, std::pair<int, int> key1) {
    StentModel::Member mem{kind, ring, static_cast<int>(s.elements.size()), n_el, 0.0};
    const double du = (seg.phi1 - seg.phi0) * R, dz = seg.z1 - seg.z0;
    mem.straight_length = std::hypot(du, dz);
    const int first_node = static_cast<int>(s.points.size());
    for (int i = 0; i <= 2 * n_el; ++i) {
      double phi, z;
      if (i == 0) {
        phi = seg.phi0;
        z = seg.z0;
      } else if (i == 2 * n_el) {
        // Going round the ring ends at 2*pi: write it as 0 so that the joint's nodes coincide bitwise.
        phi = seg.phi1 >= 2.0 * std::numbers::pi ? seg.phi1 - 2.0 * std::numbers::pi : seg.phi1;
        z = seg.z1;
      } else {
        const double xi = static_cast<double>(i) / (2 * n_el);
        phi = seg.phi0 + xi * (seg.phi1 - seg.phi0);
        z = seg.z0 + xi * (seg.z1 - seg.z0);
      }
      // Warp: X = c(sigma) + R (cos phi n + sin phi b), sigma = start + z. The
      // tangent is dX/dxi; with a rotation-minimizing frame n' = -(k.n) t,
      // b' = -(k.b) t, so dX/dz = t (1 - R (cos phi k.n + sin phi k.b)).
      const AxisFrame f = axis.frame(s.axis_start + z);
      const Eigen::Vector3d radial = std::cos(phi) * f.normal + std::sin(phi) * f.binormal;
      const Eigen::Vector3d circumferential = -std::sin(phi) * f.normal + std::cos(phi) * f.binormal;
      const double stretch = 1.0 - R * f.curvature.dot(radial);
      const Eigen::Vector3d tangent = (R * (seg.phi1 - seg.phi0) * circumferential + dz * stretch * f.tangent).normalized();
      Eigen::Matrix3d triad;
      triad.col(0) = tangent;
      triad.col(1) = radial;
      triad.col(2) = tangent.cross(radial);
      s.points.push_back(f.position + R * radial);
      s.triads.push_back(triad);
      s.node_kind.push_back(i % 2 == 0 ? StentModel::kEndNode : StentModel::kMiddleNode);
      s.unrolled.emplace_back(phi, z);
    }
    for (int e = 0; e < n_el; ++e)
      s.elements.push_back({{first_node + 2 * e, first_node + 2 * e + 2, first_node + 2 * e + 1}, static_cast<int>(s.members.size())});
    at_point[key0].push_back(first_node);
    at_point[key1].push_back(first_node + 2 * n_el);
    s.members.push_back(mem);
  };

  // Rings: strut k joins crown points k and k+1 (the last one closes the ring).
  for (int r = 0; r < d.rings; ++r) {
    for (int k = 0; k < npr; ++k) {
      auto [phi0, z0] = crown(r, k);
      auto [phi1, z1] = crown(r, k + 1);
      if (k + 1 == npr) phi1 = 2.0 * std::numbers::pi;  // same point as k = 0, reached going round
      add_member(StentModel::kStrut, r, {phi0, z0, phi1, z1}, d.elements_per_strut, {r, k}, {r, (k + 1) % npr});
    }
  }
  // Connectors: evenly spread over the crowns (peaks, odd k), rotated by half
  // their spacing in every other gap (DESIGN.md §8: shape; positions ours).
  const int spacing = d.crowns / d.connectors_per_gap;  // in crowns
  for (int g = 0; g + 1 < d.rings; ++g) {
    const int shift = (g % 2) * (spacing / 2);
    for (int j = 0; j < d.connectors_per_gap; ++j) {
      const int k = (2 * (j * spacing + shift) + 1) % npr;  // a peak of ring g
      auto [phi0, z0] = crown(g, k);
      if (d.connector_shape == ConnectorShape::peak_to_valley) {
        auto [phi1, z1] = crown(g + 1, k + 1);  // the neighbouring valley of ring g+1
        if (k + 1 == npr) phi1 = 2.0 * std::numbers::pi;
        add_member(StentModel::kConnector, g, {phi0, z0, phi1, z1}, d.elements_per_connector, {g, k}, {g + 1, (k + 1) % npr});
      } else {
        auto [phi1, z1] = crown(g + 1, k);  // the same crown of ring g+1
        add_member(StentModel::kConnector, g, {phi0, z0, phi1, z1}, d.elements_per_connector, {g, k}, {g + 1, k});
      }
    }
  }
  for (const auto& [key, nodes] : at_point)
    for (std::size_t i = 1; i < nodes.size(); ++i) s.joints.push_back({nodes[0], nodes[i]});

  // Fixations (paper 2.2): 4 end nodes at mid-length spread around the
  // circumference (targets 0, 90, 180, 270 degrees of the frame), one per
  // joint; on a straight axis one more node (target 45 degrees) fixed axially.
  std::vector<int> cluster(s.points.size(), -1);
  {
    int c = 0;
    for (const auto& [key, nodes] : at_point) {
      for (int n : nodes) cluster[static_cast<std::size_t>(n)] = c;
      ++c;
    }
  }
  double best_dz = std::numeric_limits<double>::infinity();
  for (std::size_t n = 0; n < s.points.size(); ++n)
    if (s.node_kind[n] == StentModel::kEndNode) best_dz = std::min(best_dz, std::abs(s.unrolled[n].y() - 0.5 * s.length));
  std::vector<int> used_clusters;
  auto pick = [&](double target_phi) -> int {
    int best = -1;
    double best_angle = std::numeric_limits<double>::infinity();
    for (std::size_t n = 0; n < s.points.size(); ++n) {
      if (s.node_kind[n] != StentModel::kEndNode) continue;
      if (std::abs(std::abs(s.unrolled[n].y() - 0.5 * s.length) - best_dz) > 1e-9) continue;
      const int c = cluster[n];
      if (c >= 0 && std::find(used_clusters.begin(), used_clusters.end(), c) != used_clusters.end()) continue;
      double a = std::remainder(s.unrolled[n].x() - target_phi, 2.0 * std::numbers::pi);
      a = std::abs(a);
      if (a < best_angle - 1e-12) {
        best_angle = a;
        best = static_cast<int>(n);
      }
    }
    if (best < 0) throw ComputeError("stent: no free node at mid-length for a fixation");
    if (cluster[static_cast<std::size_t>(best)] >= 0) used_clusters.push_back(cluster[static_cast<std::size_t>(best)]);
    else used_clusters.push_back(-2 - best);
    return best;
  };
  for (int q = 0; q < 4; ++q) {
    const int n = pick(q * 0.5 * std::numbers::pi);
    s.fixations.push_back({n, s.triads[static_cast<std::size_t>(n)].col(1), false});
  }
  if (axis.is_straight()) {
    const int n = pick(0.25 * std::numbers::pi);
    s.fixations.push_back({n, axis.frame(s.axis_start + s.unrolled[static_cast<std::size_t>(n)].y()).tangent, true});
  }
  return s;
}

}  // namespace stentsim::device_gen
