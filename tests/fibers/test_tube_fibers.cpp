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

// issue 5: fibers.vtu carries the transmural coordinate. On the generic artery
// (inner radius 0.8, outer 1.4 mm) it is the annulus' harmonic function
// ln(r/0.8)/ln(1.4/0.8): 0 on the endothelium, 1 on the outer wall.
TEST(TubeFibers, TransmuralCoordinateIsTheAnnulusHarmonicFunction) {
  const MeshData mesh = meshing::generic_artery_mesh({});
  const MeshData f = fibers::tube_fibers(mesh, {{tags::media, 0.0}, {tags::adventitia, 0.7}});
  const auto t = [](double r) { return std::log(r / 0.8) / std::log(1.4 / 0.8); };
  const auto& tp = f.point_data.at("Transmural");
  double tmin = 1, tmax = 0;
  for (std::size_t p = 0; p < f.points.size(); ++p) {
    ASSERT_NEAR(tp.values[p], t(std::hypot(f.points[p].x(), f.points[p].y())), 1e-12);
    tmin = std::min(tmin, tp.values[p]);
    tmax = std::max(tmax, tp.values[p]);
  }
  EXPECT_NEAR(tmin, 0.0, 1e-12);
  EXPECT_NEAR(tmax, 1.0, 1e-12);
  const auto& tc = f.cell_data.at("Transmural");
  ASSERT_EQ(tc.values.size(), f.num_cells());
  for (std::size_t c = 0; c < f.num_cells(); ++c) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (auto n : f.cell(c)) x += f.points[static_cast<std::size_t>(n)];
    x /= 8;
    ASSERT_NEAR(tc.values[c], t(std::hypot(x.x(), x.y())), 1e-12);
    // the media (inside) lies below the media/adventitia interface at r = 0.8 + 0.22
    if (static_cast<int>(f.cell_data.at(tags::kLayer).at(c)) == tags::media) ASSERT_LT(tc.values[c], t(1.02) + 1e-12);
  }
}
