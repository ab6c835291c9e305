// Phantoms: presets as DESIGN.md §8 settles them, determinism per seed, and
// the geometric facts the centerline tests rely on (the lumen surface is at
// exactly the true radius from the true centerline; outward normals; open ends).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>

#include "common/config.hpp"
#include "common/error.hpp"
#include "segmentation_io/phantom.hpp"
#include "segmentation_io/triangle_surface.hpp"

using namespace stentsim;
using namespace stentsim::segmentation;

namespace {

// Distance from p to the triangle mesh (brute force; fixtures are small).
double point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                               const Eigen::Vector3d& c) {
  // Ericson, Real-Time Collision Detection, 5.1.5.
  Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return (p - a).norm();
  Eigen::Vector3d bp = p - b;
  double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return (p - b).norm();
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  Eigen::Vector3d cp = p - c;
  double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return (p - c).norm();
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  double denom = 1 / (va + vb + vc);
  return (p - (a + ab * vb * denom + ac * vc * denom)).norm();
}

double distance_to(const TriSurface& s, const Eigen::Vector3d& p) {
  double d = 1e300;
  for (const auto& t : s.triangles)
    d = std::min(d, point_triangle_distance(p, s.points[t[0]], s.points[t[1]], s.points[t[2]]));
  return d;
}

}  // namespace

TEST(Phantom, PresetsMatchDesign) {
  auto c2 = phantom_preset("case2-rca", 1);
  EXPECT_DOUBLE_EQ(2 * c2.reference_radius, 1.9);  // DESIGN §8: 1.9 mm reference lumen
  EXPECT_DOUBLE_EQ(c2.stenosis_severity, 20.0);
  EXPECT_EQ(c2.curve, PhantomCurve::arc);
  EXPECT_DOUBLE_EQ(c2.radius_of_curvature, 10.0);
  auto g = build_phantom(c2);
  const auto& abs = g.true_centerline.point_data.at("Abscissas").values;
  EXPECT_NEAR(abs.back(), 21.0, 0.5);                      // about 21 mm
  EXPECT_NEAR(2 * g.min_radius, 1.52, 1e-3);               // 20 % obstruction leaves 1.52 mm
  std::printf("case2-rca: length %.3f mm, throat diameter %.4f mm, wall %.3f..%.3f mm\n", abs.back(), 2 * g.min_radius,
              g.wall_thickness_min, g.wall_thickness_max);
  EXPECT_NEAR(g.wall_thickness_min, 0.7, 0.02);            // wall 0.7 ..
  EXPECT_NEAR(g.wall_thickness_max, 1.8, 0.1);             // .. 1.8 mm (paper Case 2)
  auto s70 = build_phantom(phantom_preset("severe-70", 1));
  EXPECT_NEAR(s70.min_radius / 1.25, 0.3, 1e-6);
  EXPECT_LT(2 * s70.min_radius, 1.27);  // does not fit the crimped device (DESIGN §8)
  EXPECT_EQ(phantom_preset("tortuous", 1).curve, PhantomCurve::helix);
  EXPECT_DOUBLE_EQ(phantom_preset("tortuous", 1).radius_of_curvature, 5.0);
  EXPECT_THROW(phantom_preset("nonsense", 1), InputError);
}

TEST(Phantom, TortuousHasRadiusOfCurvatureFive) {
  auto g = build_phantom(phantom_preset("tortuous", 3));
  const auto& p = g.true_centerline.points;
  // Curvature of the true centerline away from the stenosis by the circle through three points.
  for (std::size_t i = 10; i + 10 < p.size(); i += 37) {
    Eigen::Vector3d a = p[i - 10], b = p[i], c = p[i + 10];
    double R = (a - b).norm() * (b - c).norm() * (c - a).norm() / (2 * (b - a).cross(c - a).norm());
    const auto& abs = g.true_centerline.point_data.at("Abscissas").values;
    if (std::abs(abs[i] - g.stenosis_abscissa) > 4) {
      EXPECT_NEAR(R, 5.0, 0.05) << "at " << abs[i] << " mm";
    }
  }
}

TEST(Phantom, DeterministicPerSeed) {
  auto a = build_phantom(phantom_preset("case2-rca", 7));
  auto b = build_phantom(phantom_preset("case2-rca", 7));
  auto c = build_phantom(phantom_preset("case2-rca", 8));
  ASSERT_EQ(a.lumen.points.size(), b.lumen.points.size());
  for (std::size_t i = 0; i < a.lumen.points.size(); ++i) ASSERT_EQ(a.lumen.points[i], b.lumen.points[i]);
  double diff = 0;
  for (std::size_t i = 0; i < std::min(a.lumen.points.size(), c.lumen.points.size()); ++i)
    diff = std::max(diff, (a.lumen.points[i] - c.lumen.points[i]).norm());
  EXPECT_GT(diff, 0.05);  // the seed changes the plaque side and the waviness
}

// The lumen is the canal surface of the true centerline: every true centerline
// point is at its true radius from the triangulated lumen (up to the chord
// sag of the triangulation, 1 − cos(π/N) ≈ 0.12 % for N = 64).
class PhantomPreset : public ::testing::TestWithParam<std::string> {};

TEST_P(PhantomPreset, TrueRadiusIsDistanceToLumen) {
  auto g = build_phantom(phantom_preset(GetParam(), 1));
  TriSurface lumen = surface_from_mesh(g.lumen, "lumen");
  const auto& rad = g.true_centerline.point_data.at("MaximumInscribedSphereRadius").values;
  const auto& abs = g.true_centerline.point_data.at("Abscissas").values;
  double worst = 0;
  for (std::size_t i = 0; i < rad.size(); i += 7) {
    if (abs[i] < 2 * rad[i] || abs.back() - abs[i] < 2 * rad[i]) continue;  // open ends
    double d = distance_to(lumen, g.true_centerline.points[i]);
    worst = std::max(worst, std::abs(d - rad[i]) / rad[i]);
  }
  std::printf("%s: max |distance to lumen - true radius| / radius = %.5f\n", GetParam().c_str(), worst);
  EXPECT_LT(worst, 0.003) << GetParam();
  // Outward normals and two open ends.
  auto loops = boundary_loops(lumen);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_GT(signed_volume(capped(lumen, loops)), 0);
  TriSurface wall = surface_from_mesh(g.wall, "wall");
  auto wloops = boundary_loops(wall);
  ASSERT_EQ(wloops.size(), 2u);
  EXPECT_GT(signed_volume(capped(wall, wloops)), signed_volume(capped(lumen, loops)));
}

INSTANTIATE_TEST_SUITE_P(All, PhantomPreset,
                         ::testing::Values("straight-healthy", "case2-rca", "severe-70", "tortuous"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (auto& ch : n)
                             if (ch == '-') ch = '_';
                           return n;
                         });

TEST(Phantom, ParseSectionWithOverridesAndErrors) {
  auto cfg = ConfigMap::from_string("phantom:\n  preset: severe-70\n  seed: 4\n  length: 30 mm\n  stenosis_severity: 50\n",
                                    "case.yaml");
  auto sec = cfg.map("phantom");
  PhantomSpec s = parse_phantom(sec);
  EXPECT_EQ(s.preset, "severe-70");
  EXPECT_EQ(s.seed, 4u);
  EXPECT_DOUBLE_EQ(s.length, 30.0);
  EXPECT_DOUBLE_EQ(s.stenosis_severity, 50.0);

  auto bad = ConfigMap::from_string("phantom:\n  preset: tortuous\n  lenght: 3\n", "case.yaml");
  auto bsec = bad.map("phantom");
  try {
    parse_phantom(bsec);
    FAIL() << "unknown key accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lenght"), std::string::npos) << e.what();
  }
  auto geo = ConfigMap::from_string("phantom:\n  preset: case2-rca\n  radius_of_curvature: 1.5 mm\n", "case.yaml");
  auto gsec = geo.map("phantom");
  try {
    parse_phantom(gsec);
    FAIL() << "self-intersecting wall accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("radius_of_curvature"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("case.yaml"), std::string::npos) << e.what();
  }
}

TEST(Phantom, WritesThreeFiles) {
  auto dir = std::filesystem::temp_directory_path() / "stentsim_test_phantom_write";
  std::filesystem::remove_all(dir);
  Summary summary;
  write_phantom(phantom_preset("straight-healthy", 1), dir, summary);
  for (const char* f : {"lumen.vtp", "wall.vtp", "centerline_true.vtp"}) EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  MeshData cl = read_vtp((dir / "centerline_true.vtp").string());
  EXPECT_EQ(cl.point_data.count("MaximumInscribedSphereRadius"), 1u);
  EXPECT_EQ(cl.point_data.at("ParallelTransportNormals").components, 3);
  MeshData lumen = read_vtp((dir / "lumen.vtp").string());
  EXPECT_EQ(lumen.field_text.at("units"), "mm");
  std::filesystem::remove_all(dir);
}
