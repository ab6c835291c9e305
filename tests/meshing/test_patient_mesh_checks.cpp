// Pre-loft checks of the wall sections (meshing/section_checks.cpp):
// consecutive sections must not meet inside the wall (a bend whose radius is
// close to the outer radius), the interface contours must be nested.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <regex>
#include <string>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"
#include "meshing/patient_mesh.hpp"
#include "tube_fixtures.hpp"

using namespace stentsim;

namespace {

meshing::PatientMeshOptions coarse() {
  meshing::PatientMeshOptions o;
  o.element = "tet4";
  o.size = 0.5;
  o.station_spacing = 0.5;
  return o;
}

std::string section_error(const test::BentPath& p, double rl, double rw, const meshing::PatientMeshOptions& o) {
  try {
    meshing::wall_sections(test::path_tube(p, rl), test::path_tube(p, rw), test::path_centerline(p), o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(PatientMeshChecks, SharpBendWithThickWallIsAnInputErrorNamingTheSections) {
  // Outer radius 2.0 mm on a bend of radius 2.1 mm: on the inner side two
  // sections 0.5 mm apart are only (1 - 2.0/2.1) = 5 % of their spacing apart,
  // below the 10 % bound. The bend spans s = 3 ... 6.3 mm.
  const test::BentPath p{3.0, 2.1, std::numbers::pi / 2, 3.0};
  const std::string msg = section_error(p, 1.0, 2.0, coarse());
  ASSERT_FALSE(msg.empty()) << "no error on the sharp bend";
  std::printf("%s\n", msg.c_str());
  std::smatch m;
  ASSERT_TRUE(std::regex_search(msg, m, std::regex(R"(sections (\d+) and (\d+) \(s = ([0-9.]+) and ([0-9.]+) mm)")))
      << msg;
  const double s0 = std::stod(m[3]), s1 = std::stod(m[4]);
  EXPECT_EQ(std::stoi(m[2]), std::stoi(m[1]) + 1);
  EXPECT_GT(s1, p.a - 0.5) << "reported before the bend";
  EXPECT_LT(s0, p.a + p.bend * p.angle + 0.5) << "reported after the bend";
  ASSERT_TRUE(std::regex_search(msg, m, std::regex(R"(bends with radius ~([0-9.]+) mm)"))) << msg;
  EXPECT_NEAR(std::stod(m[1]), p.bend, 0.15 * p.bend);
  EXPECT_NE(msg.find("station_spacing"), std::string::npos) << "no advice";
  // The position named is on the bend's inner side (x > 0 towards the centre
  // (2.1, 0, 3)) and on the outer wall: about 2.0 mm from the centerline.
  ASSERT_TRUE(std::regex_search(msg, m, std::regex(R"(near \(([-0-9.]+), ([-0-9.]+), ([-0-9.]+)\))"))) << msg;
  const Eigen::Vector3d x(std::stod(m[1]), std::stod(m[2]), std::stod(m[3]));
  const Eigen::Vector3d centre(p.bend, 0, p.a);
  EXPECT_LT((x - centre).norm(), p.bend - 1.5) << "not on the inner side of the bend";
}

TEST(PatientMeshChecks, GapBoundFollowsTheBendRadius) {
  // On the inner side the gap is (1 - r/R) cos(phi/2) of the chord between
  // two sections: r/R = 0.85 passes a 0.1 bound, 0.93 does not, and passes 0.
  auto o = coarse();
  const double rw = 1.7;
  const test::BentPath pass{2.0, rw / 0.85, 1.0, 2.0};
  EXPECT_EQ(section_error(pass, 1.0, rw, o), "");
  // The smallest gap found is the analytic one of the bend's inner side.
  const auto w = meshing::wall_sections(test::path_tube(pass, 1.0), test::path_tube(pass, rw), test::path_centerline(pass), o);
  const double ds = w.abscissa[1] - w.abscissa[0];
  EXPECT_NEAR(w.min_gap_ratio, (1 - 0.85) * std::cos(0.5 * ds / pass.bend), 0.01);
  EXPECT_NE(section_error({2.0, rw / 0.93, 1.0, 2.0}, 1.0, rw, o), "");
  o.min_section_gap_ratio = 0.0;
  EXPECT_EQ(section_error({2.0, rw / 0.93, 1.0, 2.0}, 1.0, rw, o), "");
}

TEST(PatientMeshChecks, CrossingInterfacesAreAnInputError) {
  const auto o = coarse();
  const test::BentPath straight{4.0, 1.0, 0.0, 0.0};
  auto w = meshing::wall_sections(test::path_tube(straight, 1.0), test::path_tube(straight, 2.0),
                                  test::path_centerline(straight), o);
  ASSERT_NO_THROW(meshing::check_wall_sections(w, o.min_section_gap_ratio));
  // Section 3, ray 5: the intima/media interface pushed inside the lumen.
  auto bad = w;
  bad.radius[3][1][5] = 0.9;
  try {
    meshing::check_wall_sections(bad, o.min_section_gap_ratio);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("section 3 "), std::string::npos) << msg;
    EXPECT_NE(msg.find(fmt::format("s = {:.2f} mm", w.abscissa[3])), std::string::npos) << msg;
    EXPECT_NE(msg.find("crosses"), std::string::npos) << msg;
  }
  // Radii ordered on every ray, but the lumen contour (1.1 mm) has a notch
  // (0.8 mm on one ray) against an intima/media interface at 1.11 mm: the
  // chords between rays stay nested, the lofted contours do not: the lumen's
  // interpolating spline rings past 1.11 mm beside the notch (to 1.118 mm).
  auto wiggle = w;
  for (std::size_t i = 0; i < wiggle.radius[2][0].size(); ++i) {
    wiggle.radius[2][0][i] = i == 5 ? 0.8 : 1.1;
    wiggle.radius[2][1][i] = 1.11;
    for (std::size_t k = 0; k + 1 < wiggle.radius[2].size(); ++k)
      ASSERT_LT(wiggle.radius[2][k][i], wiggle.radius[2][k + 1][i]);
  }
  try {
    meshing::check_wall_sections(wiggle, o.min_section_gap_ratio);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("section 2 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("lumen (endothelium) crosses the intima/media interface"), std::string::npos) << msg;
  }
  // The same notch with room to the interface (1.13 mm) passes.
  for (auto& r : wiggle.radius[2][1]) r = 1.13;
  EXPECT_NO_THROW(meshing::check_wall_sections(wiggle, o.min_section_gap_ratio));
}

TEST(PatientMeshChecks, ModerateBendStillMeshes) {
  // r/R = 0.8 (inner gap 20 % of the spacing): passes the check, and gmsh
  // meshes the three layers with positive elements.
  auto o = coarse();
  const test::BentPath p{1.0, 2.5, std::numbers::pi / 3, 1.0};
  const auto w = meshing::wall_sections(test::path_tube(p, 1.0), test::path_tube(p, 2.0), test::path_centerline(p), o);
  const MeshData m = meshing::mesh_wall_sections(w, o, std::filesystem::temp_directory_path() / "stentsim_test_bend.msh");
  const auto q = meshing::mesh_quality(m);
  for (int L : {tags::intima, tags::media, tags::adventitia}) EXPECT_GT(q.elements_per_layer[std::size_t(L)], 0u);
  EXPECT_GT(q.min_scaled_jacobian, 0.05);
  std::printf("bend R 2.5, r 2.0: %zu points, min scaled Jacobian %.3f, max aspect ratio %.2f\n", m.points.size(),
              q.min_scaled_jacobian, q.max_aspect_ratio);
}
