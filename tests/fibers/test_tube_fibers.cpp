#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"
#include "fibers/analytic_tube_fibers.hpp"
#include "meshing/generic_artery.hpp"

using namespace stentsim;

TEST(TubeFibers, FramesAndFamiliesFollowThePaper) {
  const double phi_a = 40.0 * M_PI / 180.0;
  const MeshData mesh = meshing::generic_artery_mesh({});
  const MeshData f = fibers::tube_fibers(mesh, {{tags::media, 0.0}, {tags::adventitia, phi_a}});
  ASSERT_EQ(f.num_cells(), 48u * 36u * 4u);  // faces skipped
  auto v = [&](const char* name, std::size_t c) {
    const auto& a = f.cell_data.at(name);
    return Eigen::Vector3d(a.at(c, 0), a.at(c, 1), a.at(c, 2));
  };
  for (std::size_t c = 0; c < f.num_cells(); ++c) {
    const Eigen::Vector3d er = v("Radial", c), et = v("Circumferential", c), ez = v("Longitudinal", c);
    ASSERT_NEAR(er.norm(), 1, 1e-12);
    ASSERT_NEAR(et.norm(), 1, 1e-12);
    ASSERT_NEAR(er.dot(et), 0, 1e-12);
    ASSERT_NEAR(er.cross(et).dot(ez), 1, 1e-12);  // right-handed
    // Radial points away from the axis at the element centroid.
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (auto n : f.cell(c)) x += f.points[static_cast<std::size_t>(n)];
    x /= 8;
    ASSERT_GT(er.dot(Eigen::Vector3d(x.x(), x.y(), 0)), 0);
    const double phi = static_cast<int>(f.cell_data.at(tags::kLayer).at(c)) == tags::media ? 0.0 : phi_a;
    ASSERT_NEAR(v("Fiber1", c).dot(et), std::cos(phi), 1e-12);
    ASSERT_NEAR(v("Fiber1", c).dot(ez), std::sin(phi), 1e-12);
    ASSERT_NEAR(v("Fiber2", c).dot(ez), -std::sin(phi), 1e-12);
    ASSERT_NEAR(v("Fiber1", c).dot(er), 0, 1e-12);
  }
}

TEST(TubeFibers, MissingLayerAngleIsAnError) {
  const MeshData mesh = meshing::generic_artery_mesh({});
  EXPECT_THROW(fibers::tube_fibers(mesh, {{tags::media, 0.0}}), InputError);
}
