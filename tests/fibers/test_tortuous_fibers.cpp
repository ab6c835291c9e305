// Fibers on the tortuous phantom (bends and a stenosis), through the stages a
// case runs: `stentsim phantom --preset tortuous` -> `stentsim centerline`
// (the extracted centerline, not the phantom's true one) -> `stentsim mesh`
// (tet10, 0.5 mm) -> harmonic_fibers in process (so the frames are checked in
// full double precision, not after the VTU round trip). Issue 5: frames
// orthonormal and right-handed, t and l within [0, 1] (discrete maximum
// principle), neighbouring fibers close, the configured angle per layer.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "common/mesh_data.hpp"
#include "common/mesh_tags.hpp"
#include "fibers/harmonic_fibers.hpp"
#include "tests/workflows/cli_runner.hpp"

namespace fs = std::filesystem;
using namespace stentsim;
using stentsim::testing::run_stentsim;
using Vec3 = Eigen::Vector3d;

TEST(TortuousFibers, PhantomCenterlineMeshFibersFramesAndAngles) {
  const fs::path dir = fs::temp_directory_path() / "stentsim_test_tortuous_fibers";
  const auto r = stentsim::testing::mesh_phantom("tortuous", dir, "--element tet10 --size 0.5");
  ASSERT_EQ(r.code, 0) << r.out;
  const MeshData mesh = read_vtu((dir / "mesh/artery.vtu").string());
  const MeshData cl = read_vtp((dir / "centerline.vtp").string());

  fibers::HarmonicFiberOptions o;
  const double deg = M_PI / 180;
  o.angles = {{tags::intima, 0.0}, {tags::media, 0.0}, {tags::adventitia, 40 * deg}};
  const auto res = fibers::harmonic_fibers(mesh, cl, o, (dir / "mesh/artery.vtu").string());
  const auto& f = res.fibers;
  const auto& q = res.quality;
  std::printf("tortuous tet10 0.5 mm: %zu cells, %zu nodes, Laplace %.1f s, orthonormality %.1e, handedness %.15f, "
              "neighbour fiber angle max %.1f deg, frame %.1f deg, t in [%.3g, %.3g], l in [%.3g, %.3g]\n",
              f.num_cells(), f.points.size(), res.laplace_seconds, q.orthonormality_error, q.min_handedness,
              q.max_neighbour_fiber_angle_deg, q.max_neighbour_frame_angle_deg, q.transmural_min, q.transmural_max,
              q.longitudinal_min, q.longitudinal_max);
  ASSERT_GT(f.num_cells(), 1000u);
  EXPECT_LT(res.transmural_residual, 1e-8);
  EXPECT_LT(res.longitudinal_residual, 1e-8);

  // Per cell, recomputed here (not only fiber_quality's figures): the frame
  // (radial, circumferential, longitudinal) orthonormal and right-handed, and
  // Fiber1/2 = cos(phi) c +/- sin(phi) l with phi the layer's angle.
  const auto& R = f.cell_data.at("Radial");
  const auto& C = f.cell_data.at("Circumferential");
  const auto& L = f.cell_data.at("Longitudinal");
  const auto& F1 = f.cell_data.at("Fiber1");
  const auto& F2 = f.cell_data.at("Fiber2");
  const auto& layer = f.cell_data.at(tags::kLayer);
  auto v = [](const DataArray& a, std::size_t c) { return Vec3(a.at(c, 0), a.at(c, 1), a.at(c, 2)); };
  double ortho = 0, hand = 1, angle_err = 0;
  std::map<int, std::size_t> per_layer;
  for (std::size_t c = 0; c < f.num_cells(); ++c) {
    Eigen::Matrix3d Q;
    Q << v(R, c), v(C, c), v(L, c);
    ortho = std::max(ortho, (Q.transpose() * Q - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff());
    hand = std::min(hand, Q.determinant());
    const int lay = int(layer.at(c));
    ++per_layer[lay];
    const double phi = o.angles.at(lay);
    const Vec3 e1 = std::cos(phi) * v(C, c) + std::sin(phi) * v(L, c), e2 = std::cos(phi) * v(C, c) - std::sin(phi) * v(L, c);
    angle_err = std::max({angle_err, (v(F1, c) - e1).norm(), (v(F2, c) - e2).norm()});
  }
  EXPECT_LT(ortho, 1e-12);
  EXPECT_NEAR(hand, 1.0, 1e-12);
  EXPECT_LT(angle_err, 1e-12);
  EXPECT_LT(q.orthonormality_error, 1e-12);
  EXPECT_EQ(per_layer.size(), 3u);  // intima, media, adventitia all present (default mesh options)
  for (auto [lay, n] : per_layer) EXPECT_GT(n, 100u) << tags::layer_name(lay);

  // Discrete maximum principle: nodal t and l within their boundary values.
  for (const char* name : {"Transmural", "LongitudinalCoordinate"}) {
    const auto& u = f.point_data.at(name).values;
    ASSERT_EQ(u.size(), f.points.size()) << name;
    const auto [lo, hi] = std::minmax_element(u.begin(), u.end());
    EXPECT_GE(*lo, -1e-8) << name;
    EXPECT_LE(*hi, 1 + 1e-8) << name;
    EXPECT_LT(*lo, 1e-12) << name;  // the boundary values are attained
    EXPECT_GT(*hi, 1 - 1e-12) << name;
  }

  // Smoothness. Between face neighbours the circumferential direction turns by
  // about h / r: 0.5 mm / ~1 mm lumen radius ~ 29 deg, more on the bends'
  // inner side and the stenosis (measured 33.4 deg at 0.5 mm). 45 deg keeps
  // that margin but catches a flipped frame (~180 deg) or a sign error of the
  // +/-40 deg adventitia family (~80 deg).
  EXPECT_LT(q.max_neighbour_fiber_angle_deg, 45.0);
  EXPECT_LT(q.max_neighbour_frame_angle_deg, 45.0);
  fs::remove_all(dir);
}
