#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"
#include "meshing/generic_artery.hpp"

using namespace stentsim;
using namespace stentsim::meshing;

namespace {
double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}
// Signed volume of a VTK hex8 by its 6-tet split around the 0-6 diagonal.
double hex_volume(const MeshData& m, const std::vector<std::int64_t>& n) {
  auto p = [&](int i) { return m.points[static_cast<std::size_t>(n[static_cast<std::size_t>(i)])]; };
  return tet_volume(p(0), p(1), p(2), p(6)) + tet_volume(p(0), p(2), p(3), p(6)) + tet_volume(p(0), p(3), p(7), p(6)) +
         tet_volume(p(0), p(7), p(4), p(6)) + tet_volume(p(0), p(4), p(5), p(6)) + tet_volume(p(0), p(5), p(1), p(6));
}
}  // namespace

TEST(GenericArtery, DefaultMeshHasThePaperSizeAndPositiveVolumes) {
  GenericArterySpec s;
  const MeshData m = generic_artery_mesh(s);
  EXPECT_EQ(m.points.size(), 48u * 5u * 37u);
  EXPECT_EQ(3 * m.points.size(), 26640u);  // paper: about 27,000 DOFs
  const auto& layer = m.cell_data.at(tags::kLayer);
  const auto& face = m.cell_data.at(tags::kFaceGroup);
  double volume = 0, media_volume = 0;
  std::size_t hex = 0, faces[5] = {0, 0, 0, 0, 0};
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    if (m.cell_types[c] == CellType::hexahedron) {
      const double v = hex_volume(m, m.cell(c));
      ASSERT_GT(v, 0) << "inverted hex " << c;
      volume += v;
      if (static_cast<int>(layer.at(c)) == tags::media) media_volume += v;
      ++hex;
      EXPECT_EQ(static_cast<int>(face.at(c)), tags::no_face);
    } else {
      ASSERT_EQ(m.cell_types[c], CellType::quad);
      ++faces[static_cast<int>(face.at(c))];
    }
  }
  EXPECT_EQ(hex, 48u * 36u * 4u);
  // The polygonal tube's exact volume: L * (n/2) sin(2 pi/n) (ro^2 - ri^2).
  const double k = 24 * std::sin(2 * std::numbers::pi / 48);
  EXPECT_NEAR(volume, 11.0 * k * (1.4 * 1.4 - 0.8 * 0.8), 1e-9);
  EXPECT_NEAR(media_volume, 11.0 * k * (1.02 * 1.02 - 0.8 * 0.8), 1e-9);
  EXPECT_EQ(faces[tags::endothelium], 48u * 36u);
  EXPECT_EQ(faces[tags::outer_wall], 48u * 36u);
  EXPECT_EQ(faces[tags::proximal_cut], 48u * 4u);
  EXPECT_EQ(faces[tags::distal_cut], 48u * 4u);
}

TEST(GenericArtery, FaceNormalsPointOutOfTheWall) {
  const MeshData m = generic_artery_mesh({});
  const auto& face = m.cell_data.at(tags::kFaceGroup);
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    if (m.cell_types[c] != CellType::quad) continue;
    const auto n = m.cell(c);
    auto p = [&](int i) { return m.points[static_cast<std::size_t>(n[static_cast<std::size_t>(i)])]; };
    const Eigen::Vector3d normal = (p(2) - p(0)).cross(p(3) - p(1));
    const Eigen::Vector3d centre = (p(0) + p(1) + p(2) + p(3)) / 4;
    const Eigen::Vector3d er = Eigen::Vector3d(centre.x(), centre.y(), 0).normalized();
    switch (static_cast<int>(face.at(c))) {
      case tags::endothelium: ASSERT_LT(normal.dot(er), 0) << c; break;
      case tags::outer_wall: ASSERT_GT(normal.dot(er), 0) << c; break;
      case tags::proximal_cut: ASSERT_LT(normal.z(), 0) << c; break;
      case tags::distal_cut: ASSERT_GT(normal.z(), 0) << c; break;
      default: FAIL() << "untagged face " << c;
    }
  }
}

TEST(GenericArtery, RejectsASpecThatCannotBeMeshed) {
  GenericArterySpec s;
  s.outer_diameter = 1.0;
  try {
    generic_artery_mesh(s);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh.generic.outer_diameter"), std::string::npos) << e.what();
  }
  s = {};
  s.elements_around = 3;
  EXPECT_THROW(generic_artery_mesh(s), InputError);
}
