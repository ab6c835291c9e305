// The balloon mesh: counts, radii, positive volumes, exact polygonal volume,
// face tags with outward normals; curved axis.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "common/config.hpp"
#include "common/error.hpp"
#include "device_gen/balloon_mesh.hpp"
#include "synthetic_curves.hpp"

using namespace stentsim;
using namespace stentsim::device_gen;

namespace {

// Volume of a hex with planar faces: 6 tetrahedra around the diagonal 0-6.
double hex_volume(const MeshData& m, std::size_t c) {
  const auto n = m.cell(c);
  auto p = [&](int i) { return m.points[static_cast<std::size_t>(n[static_cast<std::size_t>(i)])]; };
  static constexpr int tets[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
  double v = 0;
  for (const auto& t : tets) v += (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).dot(p(t[3]) - p(t[0])) / 6.0;
  return v;
}

int count_faces(const MeshData& m, int group) {
  int k = 0;
  for (double r : m.cell_data.at(tags::kFaceGroup).values) k += static_cast<int>(r) == group;
  return k;
}

int count_wall_cells(const MeshData& m) {
  int k = 0;
  for (double r : m.cell_data.at(tags::kLayer).values) k += static_cast<int>(r) == tags::balloon_wall;
  return k;
}

}  // namespace

TEST(DeviceGenBalloon, PaperCountsAndGeometryStraight) {
  const BalloonDesign d;
  EXPECT_EQ(d.around(), 29);
  EXPECT_EQ(d.along(), 44);
  const MeshData m = build_balloon_mesh(d, DeviceAxis::straight(d.length));
  EXPECT_EQ(count_wall_cells(m), 1276);
  EXPECT_EQ(m.points.size(), 29u * 45u * 2u);
  EXPECT_EQ(count_faces(m, tags::balloon_inner), 1276);
  EXPECT_EQ(count_faces(m, tags::balloon_outer), 1276);
  EXPECT_EQ(count_faces(m, tags::balloon_end_proximal), 29);
  EXPECT_EQ(count_faces(m, tags::balloon_end_distal), 29);
  const auto& tags = m.point_data.at("NodeTag");
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const int tag = static_cast<int>(tags.values[i]);
    const double r = m.points[i].head<2>().norm();
    EXPECT_NEAR(r, (tag & kNodeInner) ? 0.45 : 0.49, 1e-12);
    EXPECT_EQ((tag & kNodeProximal) != 0, std::abs(m.points[i].z() + 4.7) < 1e-12);
    EXPECT_EQ((tag & kNodeDistal) != 0, std::abs(m.points[i].z() - 4.7) < 1e-12);
  }
  double volume = 0;
  for (std::size_t c = 0; c < 1276; ++c) {
    const double v = hex_volume(m, c);
    EXPECT_GT(v, 0.0);
    volume += v;
  }
  // Polygonal annulus (29-gon) times length: exact for planar-faced hexes.
  const double exact = 9.4 * 29 / 2.0 * std::sin(2 * std::numbers::pi / 29) * (0.49 * 0.49 - 0.45 * 0.45);
  EXPECT_NEAR(volume, exact, 1e-12);
  // Face normals point out of the wall.
  const auto& role = m.cell_data.at(tags::kFaceGroup).values;
  for (std::size_t c = 1276; c < m.num_cells(); ++c) {
    const auto n = m.cell(c);
    auto p = [&](int i) { return m.points[static_cast<std::size_t>(n[static_cast<std::size_t>(i)])]; };
    const Eigen::Vector3d normal = (p(2) - p(0)).cross(p(3) - p(1));
    const Eigen::Vector3d centre = 0.25 * (p(0) + p(1) + p(2) + p(3));
    const Eigen::Vector3d radial(centre.x(), centre.y(), 0.0);
    switch (static_cast<int>(role[c])) {
      case tags::balloon_inner: EXPECT_LT(normal.dot(radial), 0.0); break;
      case tags::balloon_outer: EXPECT_GT(normal.dot(radial), 0.0); break;
      case tags::balloon_end_proximal: EXPECT_LT(normal.z(), 0.0); break;
      case tags::balloon_end_distal: EXPECT_GT(normal.z(), 0.0); break;
      default: ADD_FAILURE() << "unexpected face role";
    }
  }
}

TEST(DeviceGenBalloon, EighteenMillimetreCountsAndParsing) {
  auto cfg = ConfigMap::from_string("length: 18 mm\nelements_around: 35\nelements_along: 79\n", "case.yaml");
  const BalloonDesign d = parse_balloon_design(cfg);
  const MeshData m = build_balloon_mesh(d, DeviceAxis::straight(d.length));
  EXPECT_EQ(count_wall_cells(m), 2765);
  EXPECT_EQ(m.points.size() * 3, 16800u);  // the paper's balloon DOFs
  BalloonDesign by_size;
  by_size.length = 18.0;
  EXPECT_EQ(by_size.around() * by_size.along(), 29 * 84);  // defaults by target size
  auto bad = ConfigMap::from_string("outer_diameter: 0.98 mm\nwall_thickness: 0.5 mm\n", "case.yaml");
  EXPECT_THROW(parse_balloon_design(bad), InputError);
}

TEST(DeviceGenBalloon, CurvedAxisKeepsWallNormalToAxis) {
  const SplineCurve curve = synthetic::fit_curve(synthetic::planar_arc(10.0), 12.0);
  const DeviceAxis axis = DeviceAxis::along(curve, 6.0, 9.4, Eigen::Vector3d::UnitZ());
  const BalloonDesign d;
  const MeshData m = build_balloon_mesh(d, axis);
  for (std::size_t c = 0; c < 1276; ++c) EXPECT_GT(hex_volume(m, c), 0.0);
  const auto& tags = m.point_data.at("NodeTag");
  for (int j = 0; j <= 44; ++j) {
    const AxisFrame f = axis.frame(9.4 * j / 44);
    for (int i = 0; i < 29; ++i)
      for (int layer = 0; layer < 2; ++layer) {
        const std::size_t n = static_cast<std::size_t>((j * 29 + i) * 2 + layer);
        EXPECT_NEAR((m.points[n] - f.position).norm(), layer == 0 ? 0.45 : 0.49, 1e-12);
        EXPECT_NEAR((m.points[n] - f.position).dot(f.tangent), 0.0, 1e-12);
        EXPECT_EQ(static_cast<int>(tags.values[n]) & 3, layer == 0 ? kNodeInner : kNodeOuter);
      }
  }
}
