// The stent: counts, strut lengths, diameter, triads, joints and fixations on
// the straight axis; the warp onto a curved axis (arc length, frame, joints).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <set>

#include "common/config.hpp"
#include "common/error.hpp"
#include "device_gen/device_axis.hpp"
#include "device_gen/stent_design.hpp"
#include "device_gen/stent_mesh.hpp"
#include "device_gen/stent_model.hpp"
#include "synthetic_curves.hpp"

using namespace stentsim;
using namespace stentsim::device_gen;

namespace {

StentDesign design_with(int rings, ConnectorShape shape = ConnectorShape::peak_to_valley) {
  StentDesign d;
  d.rings = rings;
  d.connector_shape = shape;
  return d;
}

void expect_orthonormal_triads(const StentModel& s) {
  for (std::size_t n = 0; n < s.triads.size(); ++n) {
    const Eigen::Matrix3d& T = s.triads[n];
    EXPECT_LT((T.transpose() * T - Eigen::Matrix3d::Identity()).norm(), 1e-12) << "node " << n;
    EXPECT_NEAR(T.determinant(), 1.0, 1e-12) << "node " << n;
  }
}

void expect_joints_coincide(const StentModel& s) {
  for (const auto& j : s.joints)
    EXPECT_EQ((s.points[static_cast<std::size_t>(j[0])] - s.points[static_cast<std::size_t>(j[1])]).norm(), 0.0)
        << "joint " << j[0] << "-" << j[1];
}

}  // namespace

TEST(DeviceGenStent, CountsForFourAndElevenRings) {
  for (auto shape : {ConnectorShape::peak_to_valley, ConnectorShape::axial}) {
    const StentDesign d4 = design_with(4, shape);
    const StentModel s4 = build_stent(d4, DeviceAxis::straight(9.4));
    EXPECT_DOUBLE_EQ(s4.length, 6.0);
    EXPECT_EQ(s4.elements.size(), 210u);
    EXPECT_EQ(d4.beam_elements(), 210);
    EXPECT_EQ(s4.members.size(), 70u);
    EXPECT_EQ(s4.points.size(), 490u);  // 70 members x 7 nodes
    EXPECT_EQ(s4.nodal_dofs(), 3150);   // 70 x (4 x 9 + 3 x 3)
    EXPECT_EQ(s4.joints.size(), 4u * 16u + 6u * 2u);  // crowns + both ends of 6 connectors

    const StentDesign d11 = design_with(11, shape);
    const StentModel s11 = build_stent(d11, DeviceAxis::straight(18.0));
    EXPECT_DOUBLE_EQ(s11.length, 16.5);
    EXPECT_EQ(s11.elements.size(), 588u);
    EXPECT_EQ(s11.points.size(), 196u * 7u);
    EXPECT_EQ(s11.nodal_dofs(), 8820);
    const MeshData m = stent_to_mesh(s11, d11);
    int beams = 0;
    for (double r : m.cell_data.at("CellRole").values) beams += static_cast<int>(r) == kStentBeam;
    EXPECT_EQ(beams, 588);
  }
}

TEST(DeviceGenStent, StrutAndConnectorLengthsAndDiameter) {
  const StentDesign d = design_with(4);
  const StentModel s = build_stent(d, DeviceAxis::straight(9.4));
  const double R = 0.575;
  const double strut = std::hypot(1.5, std::numbers::pi * 1.15 / 16.0);
  EXPECT_NEAR(strut, 1.51690, 1e-5);
  EXPECT_NEAR(d.strut_length(), strut, 1e-15);
  for (std::size_t n = 0; n < s.points.size(); ++n) EXPECT_NEAR(2.0 * s.points[n].head<2>().norm(), 1.15, 1e-12);
  for (const auto& mem : s.members) {
    const double expected = mem.kind == StentModel::kStrut ? strut : std::numbers::pi * 1.15 / 16.0;
    EXPECT_NEAR(mem.straight_length, expected, 1e-12);
    // Along the helix on the cylinder: 6 equal chords between the 7 nodes.
    const int first = s.elements[static_cast<std::size_t>(mem.first_element)].nodes[0];
    double chords = 0;
    for (int i = 0; i < 6; ++i)
      chords += (s.points[static_cast<std::size_t>(first + i + 1)] - s.points[static_cast<std::size_t>(first + i)]).norm();
    const double dphi = (mem.kind == StentModel::kStrut ? 2 * std::numbers::pi / 16 : 2 * std::numbers::pi / 16) / 6;
    const double dz = mem.kind == StentModel::kStrut ? 0.25 : 0.0;
    EXPECT_NEAR(chords, 6 * std::hypot(2 * R * std::sin(dphi / 2), dz), 1e-12);
    EXPECT_NEAR(chords, expected, 2e-4);
  }
  // The axial connector option: 1.5 mm along the axis.
  const StentModel a = build_stent(design_with(4, ConnectorShape::axial), DeviceAxis::straight(9.4));
  for (const auto& mem : a.members)
    if (mem.kind == StentModel::kConnector) {
      EXPECT_NEAR(mem.straight_length, 1.5, 1e-12);
    }
}

TEST(DeviceGenStent, TriadsFollowTheBeamAndJointsCoincide) {
  const StentModel s = build_stent(design_with(4), DeviceAxis::straight(9.4));
  expect_orthonormal_triads(s);
  expect_joints_coincide(s);
  for (const auto& mem : s.members) {
    // e1 is the helix tangent R dphi e_phi + dz e_z; e2 is radial outward.
    const int first = s.elements[static_cast<std::size_t>(mem.first_element)].nodes[0];
    const Eigen::Vector2d u0 = s.unrolled[static_cast<std::size_t>(first)];
    Eigen::Vector2d u1 = s.unrolled[static_cast<std::size_t>(first + 6)];
    if (u1.x() < u0.x() - 1.0) u1.x() += 2 * std::numbers::pi;
    for (int i = 0; i <= 6; ++i) {
      const std::size_t n = static_cast<std::size_t>(first + i);
      const double phi = s.unrolled[n].x();
      const Eigen::Vector3d e_phi(-std::sin(phi), std::cos(phi), 0.0), e_r(std::cos(phi), std::sin(phi), 0.0);
      const Eigen::Vector3d e1 = (0.575 * (u1.x() - u0.x()) * e_phi + (u1.y() - u0.y()) * Eigen::Vector3d::UnitZ()).normalized();
      EXPECT_LT((s.triads[n].col(0) - e1).norm(), 1e-12);
      EXPECT_LT((s.triads[n].col(1) - e_r).norm(), 1e-12);
      EXPECT_LT((s.points[n] - 0.575 * e_r - Eigen::Vector3d(0, 0, s.unrolled[n].y() - 3.0)).norm(), 1e-12);
    }
  }
  // Every member owns its nodes: no node is in two members.
  std::vector<int> owner(s.points.size(), -1);
  for (const auto& e : s.elements)
    for (int n : e.nodes) {
      EXPECT_TRUE(owner[static_cast<std::size_t>(n)] == -1 || owner[static_cast<std::size_t>(n)] == e.member);
      owner[static_cast<std::size_t>(n)] = e.member;
    }
}

TEST(DeviceGenStent, FixationsAtMidLengthSpreadAround) {
  const StentModel s = build_stent(design_with(4), DeviceAxis::straight(9.4));
  ASSERT_EQ(s.fixations.size(), 5u);  // straight: 4 radial + 1 axial
  std::set<int> nodes;
  for (int q = 0; q < 4; ++q) {
    const auto& f = s.fixations[static_cast<std::size_t>(q)];
    EXPECT_FALSE(f.axial);
    const Eigen::Vector3d p = s.points[static_cast<std::size_t>(f.node)];
    EXPECT_NEAR(p.z(), 0.0, 1e-12);  // mid-length of the stent on the centred axis
    EXPECT_NEAR(std::atan2(p.y(), p.x()), std::remainder(q * std::numbers::pi / 2, 2 * std::numbers::pi), 1e-12);
    EXPECT_LT((f.direction - Eigen::Vector3d(p.x(), p.y(), 0).normalized()).norm(), 1e-12);
    EXPECT_EQ(s.node_kind[static_cast<std::size_t>(f.node)], StentModel::kEndNode);
    nodes.insert(f.node);
  }
  EXPECT_TRUE(s.fixations[4].axial);
  EXPECT_LT((s.fixations[4].direction - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
  nodes.insert(s.fixations[4].node);
  EXPECT_EQ(nodes.size(), 5u);
  // 11 rings: mid-length (8.25 mm) falls inside ring 5; the nearest end nodes are 0.25 mm away.
  const StentModel s11 = build_stent(design_with(11), DeviceAxis::straight(18.0));
  for (int q = 0; q < 4; ++q)
    EXPECT_NEAR(std::abs(s11.points[static_cast<std::size_t>(s11.fixations[static_cast<std::size_t>(q)].node)].z()), 0.25, 1e-12);
}

TEST(DeviceGenStent, RejectsStentLongerThanBalloon) {
  EXPECT_THROW(build_stent(design_with(11), DeviceAxis::straight(9.4)), InputError);
}

TEST(DeviceGenStent, ParsesDesignWithUnitsAndRejectsUnknownKeys) {
  auto cfg = ConfigMap::from_string("crowns: 8\nlength: 16.5 mm\ncrimped_diameter: 1150 um\nconnector_shape: axial\n", "case.yaml");
  const StentDesign d = parse_stent_design(cfg);
  EXPECT_EQ(d.rings, 11);
  EXPECT_NEAR(d.crimped_diameter, 1.15, 1e-12);
  EXPECT_EQ(d.connector_shape, ConnectorShape::axial);
  EXPECT_NEAR(d.envelope_diameter(), 1.27, 1e-12);
  auto bad = ConfigMap::from_string("ringz: 4\n", "case.yaml");
  EXPECT_THROW(parse_stent_design(bad), InputError);
  auto both = ConfigMap::from_string("rings: 4\nlength: 6 mm\n", "case.yaml");
  EXPECT_THROW(parse_stent_design(both), InputError);
}

// Warp onto a curved axis: the axis keeps arc length (sigma), the nodes sit
// on circles of radius R normal to the axis, triads stay orthonormal with e1
// along the warped beam, and joints still coincide.
TEST(DeviceGenStent, WarpOntoArcKeepsArcLengthAndJoints) {
  const auto arc = synthetic::planar_arc(10.0);
  const SplineCurve curve = synthetic::fit_curve(arc, 12.0);
  const DeviceAxis axis = DeviceAxis::along(curve, 6.0, 9.4, Eigen::Vector3d::UnitZ());
  const StentDesign d = design_with(4);
  const StentModel s = build_stent(d, axis);
  // Arc length of the stent axis between its ends by fine chords (error ~ L k^2 h^2 / 24 < 1e-11).
  const double a = s.axis_start, b = s.axis_start + s.length;
  const int n = 40000;
  double len = 0;
  Eigen::Vector3d prev = axis.position(a);
  for (int i = 1; i <= n; ++i) {
    const Eigen::Vector3d p = axis.position(a + (b - a) * i / n);
    len += (p - prev).norm();
    prev = p;
  }
  EXPECT_NEAR(len / (b - a), 1.0, 1e-9);
  // The axis lies on the arc (radius 10 about (0, 10, 0)).
  for (double sg = 0; sg <= 9.4; sg += 0.47) EXPECT_NEAR((axis.position(sg) - Eigen::Vector3d(0, 10, 0)).norm(), 10.0, 2e-6);  // s = 1e-10: near-interpolation
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const AxisFrame f = axis.frame(s.axis_start + s.unrolled[i].y());
    EXPECT_NEAR((s.points[i] - f.position).norm(), 0.575, 1e-12);
    EXPECT_NEAR((s.points[i] - f.position).dot(f.tangent), 0.0, 1e-12);
  }
  expect_orthonormal_triads(s);
  expect_joints_coincide(s);
  // e1 is the tangent of the warped beam: central differences of the warp map.
  for (const auto& mem : s.members) {
    const int first = s.elements[static_cast<std::size_t>(mem.first_element)].nodes[0];
    const Eigen::Vector2d u0 = s.unrolled[static_cast<std::size_t>(first)];
    Eigen::Vector2d u1 = s.unrolled[static_cast<std::size_t>(first + 6)];
    if (u1.x() < u0.x() - 1.0) u1.x() += 2 * std::numbers::pi;
    auto warp = [&](double xi) {
      const Eigen::Vector2d u = u0 + xi * (u1 - u0);
      const AxisFrame f = axis.frame(s.axis_start + u.y());
      return Eigen::Vector3d(f.position + 0.575 * (std::cos(u.x()) * f.normal + std::sin(u.x()) * f.binormal));
    };
    for (int i = 0; i <= 6; ++i) {
      const double xi = i / 6.0, h = 1e-5;
      const Eigen::Vector3d fd = (warp(xi + h) - warp(xi - h)).normalized();
      EXPECT_GT(s.triads[static_cast<std::size_t>(first + i)].col(0).dot(fd), 1.0 - 1e-9);
    }
  }
  EXPECT_EQ(s.fixations.size(), 4u);  // curved: no axial fixation
}
