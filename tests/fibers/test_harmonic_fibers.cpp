// Harmonic-lifting fibers (fibers/harmonic_fibers.*): against the analytic
// tube fibers on straight tubes, orthonormal/right-handed/smooth frames on a
// bent tube, boundary values and the discrete maximum principle of the
// Laplace solutions, and errors on bad input.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"
#include "fibers/analytic_tube_fibers.hpp"
#include "fibers/harmonic_fibers.hpp"
#include "fibers/tagged_tube.hpp"
#include "solver/io/generated_meshes.hpp"
#include "tests/workflows/cli_runner.hpp"

using namespace stentsim;
using Vec3 = Eigen::Vector3d;

namespace {
constexpr double kRi = 0.8, kRo = 1.4, kLength = 3.0;
const double kPhiA = 40.0 * M_PI / 180.0;

fibers::LayerAngles angles() { return {{tags::intima, 0.0}, {tags::media, 0.0}, {tags::adventitia, kPhiA}}; }

/// The straight tagged tube (tet4 or tet10) of the fiber tests.
MeshData tube(bool quadratic, int nr = 4, int nt = 64, int nz = 8) {
  fibers::TaggedTubeSpec s;
  s.inner_radius = kRi, s.outer_radius = kRo, s.length = kLength;
  s.elements_radial = nr, s.elements_around = nt, s.elements_along = nz, s.quadratic = quadratic;
  return fibers::tagged_tube(s);
}

MeshData line(const std::vector<Vec3>& pts) {
  MeshData c;
  c.points = pts;
  std::vector<std::int64_t> ids(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) ids[i] = static_cast<std::int64_t>(i);
  c.add_cell(CellType::polyline, ids);
  return c;
}

MeshData straight_centerline(bool reversed = false) {
  std::vector<Vec3> p;
  for (int i = 0; i <= 30; ++i) p.push_back(Vec3(0, 0, -0.5 + (kLength + 1.0) * i / 30.0));
  if (reversed) std::reverse(p.begin(), p.end());
  return line(p);
}

Vec3 get(const MeshData& m, const char* name, std::size_t c) {
  const auto& a = m.cell_data.at(name);
  return {a.at(c, 0), a.at(c, 1), a.at(c, 2)};
}
double deg(const Vec3& a, const Vec3& b) { return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180 / M_PI; }

struct AngleErrors {
  double mean = 0, max = 0;
};

/// Angle errors of every frame vector and fiber against the analytic tube fibers.
AngleErrors compare_with_analytic(const MeshData& mesh, const MeshData& h) {
  const MeshData a = fibers::tube_fibers(mesh, angles());
  EXPECT_EQ(a.num_cells(), h.num_cells());
  AngleErrors e;
  std::size_t n = 0;
  for (std::size_t c = 0; c < a.num_cells(); ++c)
    for (const char* name : {"Radial", "Circumferential", "Longitudinal", "Fiber1", "Fiber2"}) {
      const double d = deg(get(a, name, c), get(h, name, c));
      e.mean += d, e.max = std::max(e.max, d), ++n;
    }
  e.mean /= static_cast<double>(n);
  return e;
}

void expect_boundary_values(const MeshData& mesh, const MeshData& h) {
  const auto& t = h.point_data.at("Transmural");
  const auto& l = h.point_data.at("LongitudinalCoordinate");
  const auto& g = mesh.cell_data.at(tags::kFaceGroup);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const int grp = static_cast<int>(g.at(c));
    for (auto n : mesh.cell(c)) {
      const auto i = static_cast<std::size_t>(n);
      if (grp == tags::endothelium) ASSERT_NEAR(t.at(i), 0.0, 1e-12);
      if (grp == tags::outer_wall) ASSERT_NEAR(t.at(i), 1.0, 1e-12);
      if (grp == tags::proximal_cut) ASSERT_NEAR(l.at(i), 0.0, 1e-12);
      if (grp == tags::distal_cut) ASSERT_NEAR(l.at(i), 1.0, 1e-12);
    }
  }
}
std::string fmt_dir() { return "stentsim_fibers_cli_" + std::to_string(::getpid()); }
}  // namespace

TEST(HarmonicFibers, StraightTubeTet4MatchesAnalytic) {
  const MeshData mesh = tube(false);
  fibers::HarmonicFiberOptions o;
  o.angles = angles();
  o.linear_solver = solver::LinearSolverType::direct;
  const auto r = fibers::harmonic_fibers(mesh, straight_centerline(), o);
  const auto e = compare_with_analytic(mesh, r.fibers);
  std::printf("tet4 tube: mean angle error %.4f deg, max %.4f deg, neighbour fiber angle max %.2f deg, t in [%.3g, %.3g]\n",
              e.mean, e.max, r.quality.max_neighbour_fiber_angle_deg, r.quality.transmural_min, r.quality.transmural_max);
  EXPECT_LT(e.mean, 0.5);
  EXPECT_LT(e.max, 2.0);
  expect_boundary_values(mesh, r.fibers);
  // Discrete maximum principle (tet4): nodal t and l within their boundary values.
  EXPECT_GE(r.quality.transmural_min, -1e-9);
  EXPECT_LE(r.quality.transmural_max, 1 + 1e-9);
  EXPECT_GE(r.quality.longitudinal_min, -1e-9);
  EXPECT_LE(r.quality.longitudinal_max, 1 + 1e-9);
  EXPECT_LT(r.transmural_residual, 1e-8);
}

// The defaults on tet10: t quadratic (all 10 nodes), l on the corner nodes.
TEST(HarmonicFibers, StraightTubeTet10MatchesAnalyticWithReversedCenterline) {
  const MeshData mesh = tube(true, 3, 48, 6);
  fibers::HarmonicFiberOptions o;
  o.angles = angles();
  // The centerline's direction must not matter: grad l orients it.
  const auto r = fibers::harmonic_fibers(mesh, straight_centerline(true), o);
  const auto e = compare_with_analytic(mesh, r.fibers);
  std::printf("tet10 tube (%zu nodes): Laplace %.2f s, %d + %d iterations; mean angle error %.4f deg, max %.4f deg, "
              "t in [%.4g, %.4g], l in [%.4g, %.4g]\n",
              mesh.points.size(), r.laplace_seconds, r.transmural_iterations, r.longitudinal_iterations, e.mean,
              e.max, r.quality.transmural_min, r.quality.transmural_max, r.quality.longitudinal_min,
              r.quality.longitudinal_max);
  EXPECT_LT(e.mean, 0.5);
  EXPECT_LT(e.max, 2.0);
  EXPECT_EQ(r.transmural_unknowns, mesh.points.size());
  expect_boundary_values(mesh, r.fibers);
  // tet10 has no discrete maximum principle in general; we check the nodal
  // values overshoot their boundary values by at most 1 % of the range.
  EXPECT_GE(r.quality.transmural_min, -0.01);
  EXPECT_LE(r.quality.transmural_max, 1.01);
  EXPECT_GE(r.quality.longitudinal_min, -0.01);
  EXPECT_LE(r.quality.longitudinal_max, 1.01);
  EXPECT_LT(r.quality.orthonormality_error, 1e-12);
}

/// The tube bent about a circle of radius R in the x-z plane (a quarter torus
/// section): frames must stay orthonormal, right-handed, smooth and follow the bend.
TEST(HarmonicFibers, BentTubeFramesAreOrthonormalRightHandedAndSmooth) {
  const double bend = 6.0;  // mm radius of curvature
  fibers::TaggedTubeSpec spec;
  spec.inner_radius = kRi, spec.outer_radius = kRo, spec.length = kLength;
  spec.elements_radial = 4, spec.elements_around = 48, spec.elements_along = 16, spec.bend_radius = bend;
  const MeshData mesh = fibers::tagged_tube(spec);
  fibers::HarmonicFiberOptions o;
  o.angles = angles();
  o.linear_solver = solver::LinearSolverType::direct;
  const auto r = fibers::harmonic_fibers(mesh, fibers::tagged_tube_axis(spec, 0.3, 40), o);
  const auto& q = r.quality;
  std::printf("bent tube: orthonormality %.2e, handedness min %.6f, neighbour fiber angle max %.2f deg, frame %.2f deg, "
              "tangent vs grad l max %.2f deg\n",
              q.orthonormality_error, q.min_handedness, q.max_neighbour_fiber_angle_deg, q.max_neighbour_frame_angle_deg,
              q.tangent_blend_angle_max_deg);
  EXPECT_LT(q.orthonormality_error, 1e-12);
  EXPECT_NEAR(q.min_handedness, 1.0, 1e-12);
  // 48 elements around: the analytic circumferential direction turns 7.5 deg
  // between neighbours; a smooth field stays within twice that.
  EXPECT_LT(q.max_neighbour_fiber_angle_deg, 15.0);
  EXPECT_LT(q.max_neighbour_frame_angle_deg, 15.0);
  // The longitudinal direction follows the centerline tangent of the bend.
  double worst = 0;
  const auto& f = r.fibers;
  for (std::size_t c = 0; c < f.num_cells(); ++c) {
    Vec3 x = Vec3::Zero();
    for (auto n : f.cell(c)) x += f.points[static_cast<std::size_t>(n)];
    x /= 4;
    const double a = std::atan2(x.z(), bend - x.x());
    worst = std::max(worst, deg(get(f, "Longitudinal", c), Vec3(std::sin(a), 0, std::cos(a))));
  }
  std::printf("bent tube: longitudinal vs bend tangent max %.2f deg\n", worst);
  EXPECT_LT(worst, 10.0);
  expect_boundary_values(mesh, r.fibers);
  EXPECT_GE(q.transmural_min, -1e-9);
  EXPECT_LE(q.transmural_max, 1 + 1e-9);
}

TEST(HarmonicFibers, BadInputIsAnError) {
  fibers::HarmonicFiberOptions o;
  o.angles = angles();
  o.linear_solver = solver::LinearSolverType::direct;
  const MeshData good = tube(false, 2, 16, 2);
  MeshData no_groups = good;
  no_groups.cell_data.erase(tags::kFaceGroup);
  EXPECT_THROW(fibers::harmonic_fibers(no_groups, straight_centerline(), o), InputError);
  MeshData no_distal = good;
  for (auto& v : no_distal.cell_data.at(tags::kFaceGroup).values)
    if (v == tags::distal_cut) v = tags::outer_wall;
  EXPECT_THROW(fibers::harmonic_fibers(no_distal, straight_centerline(), o), InputError);
  MeshData no_faces = solver::hex8_to_tet4(solver::ring_sector_hex8(kRi, kRo, 2 * M_PI, kLength, 2, 16, 2));
  no_faces.cell_data[tags::kLayer] = {1, std::vector<double>(no_faces.num_cells(), tags::media)};
  no_faces.cell_data[tags::kFaceGroup] = {1, std::vector<double>(no_faces.num_cells(), 0)};
  EXPECT_THROW(fibers::harmonic_fibers(no_faces, straight_centerline(), o), InputError);
  MeshData no_layer = good;
  no_layer.cell_data.erase(tags::kLayer);
  EXPECT_THROW(fibers::harmonic_fibers(no_layer, straight_centerline(), o), InputError);
  fibers::HarmonicFiberOptions missing = o;
  missing.angles.erase(tags::adventitia);
  EXPECT_THROW(fibers::harmonic_fibers(good, straight_centerline(), missing), InputError);
  EXPECT_THROW(fibers::harmonic_fibers(good, MeshData{}, o), InputError);
}

TEST(HarmonicFibers, CliWritesFibersAndSummaryAndRejectsMeshWithoutFaceGroups) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / fmt_dir();
  fs::remove_all(dir);
  fs::create_directories(dir);
  const MeshData mesh = tube(true, 2, 32, 4);
  write_vtu((dir / "artery.vtu").string(), mesh);
  write_vtp((dir / "centerline.vtp").string(), straight_centerline());
  // Issue 5's bounds with the stage's defaults (tet10: t quadratic, l on the
  // corner nodes), on a coarse tube: two tet10 through the 0.6 mm wall.
  const auto r = stentsim::testing::run_stentsim("fibers --mesh " + (dir / "artery.vtu").string() + " --centerline " +
                                       (dir / "centerline.vtp").string() + " --out " + (dir / "out/fibers.vtu").string() +
                                       " --adventitia-angle 40");
  ASSERT_EQ(r.code, 0) << r.out;
  ASSERT_TRUE(fs::exists(dir / "out/summary.yaml"));
  const MeshData f = read_vtu((dir / "out/fibers.vtu").string());
  const auto e = compare_with_analytic(mesh, f);
  EXPECT_LT(e.mean, 0.5);
  EXPECT_LT(e.max, 2.0);
  // --quadratic-laplace: both problems quadratic (l = z/L is linear, so the same frames up to the solver tolerance).
  const auto rq = stentsim::testing::run_stentsim("fibers --mesh " + (dir / "artery.vtu").string() + " --centerline " +
                                        (dir / "centerline.vtp").string() + " --out " +
                                        (dir / "quadratic/fibers.vtu").string() + " --linear-solver direct --quadratic-laplace");
  ASSERT_EQ(rq.code, 0) << rq.out;
  const auto eq = compare_with_analytic(mesh, read_vtu((dir / "quadratic/fibers.vtu").string()));
  std::printf("CLI fibers on the tet10 tube: defaults mean %.3f max %.3f deg; --quadratic-laplace mean %.3f max %.3f deg\n",
              e.mean, e.max, eq.mean, eq.max);
  EXPECT_NEAR(eq.mean, e.mean, 1e-6);
  EXPECT_NEAR(eq.max, e.max, 1e-5);
  EXPECT_TRUE(f.point_data.count("Transmural"));
  EXPECT_TRUE(f.cell_data.count("Transmural"));

  MeshData bad = mesh;
  bad.cell_data.erase(tags::kFaceGroup);
  write_vtu((dir / "bad.vtu").string(), bad);
  const auto b = stentsim::testing::run_stentsim("fibers --mesh " + (dir / "bad.vtu").string() + " --centerline " +
                                       (dir / "centerline.vtp").string() + " --out " + (dir / "bad/fibers.vtu").string());
  EXPECT_NE(b.code, 0);
  EXPECT_NE(b.out.find("FaceGroup"), std::string::npos) << b.out;
  EXPECT_FALSE(fs::exists(dir / "bad/fibers.vtu"));
  fs::remove_all(dir);
}
