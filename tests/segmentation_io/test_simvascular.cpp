// SimVascular project input (issue 3): .pth/.ctgr fixtures in data/ written in
// SimVascular's format (version 1.0 element and attribute names); the lofted
// tube of circular contours on a straight path has the circles' radius and
// the cylinder's volume, and bad files are errors naming file and element.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "segmentation_io/segmentation_stage.hpp"
#include "segmentation_io/simvascular_io.hpp"

using namespace stentsim;
using namespace stentsim::segmentation;
namespace fs = std::filesystem;

namespace {
const fs::path kData = fs::path(__FILE__).parent_path() / "data";

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(SimVascular, ReadsPathAndContours) {
  SvPath p = read_simvascular_path(kData / "straight_lad.pth");
  ASSERT_EQ(p.points.size(), 41u);
  EXPECT_NEAR(p.points.back().z(), 12.0, 1e-12);
  EXPECT_NEAR(p.tangents[3].z(), 1.0, 1e-12);
  auto c = read_simvascular_contours(kData / "straight_lad_lumen.ctgr");
  ASSERT_EQ(c.size(), 5u);
  EXPECT_EQ(c[0].type, "Circle");
  EXPECT_EQ(c[0].points.size(), 48u);
  EXPECT_EQ(c[1].id, 3);  // stored out of order in the file
}

TEST(SimVascular, LoftedStraightTubeHasTheContoursRadiusAndVolume) {
  SvPath p = read_simvascular_path(kData / "straight_lad.pth");
  LoftOptions o;
  o.points_per_contour = 64;
  TriSurface s = loft_contours(p, read_simvascular_contours(kData / "straight_lad_lumen.ctgr"), o, "lumen");
  const double R = 1.5, L = 12.0, n = 48;
  // Contour points lie on the circle; resampled points lie on the 48-gon's
  // chords, at most R(1 − cos(π/48)) = 0.0032 mm inside it.
  const double sag = R * (1 - std::cos(M_PI / n));
  double rmin = 1e9, rmax = 0, zmin = 1e9, zmax = -1e9;
  for (const auto& x : s.points) {
    double r = std::hypot(x.x(), x.y());
    rmin = std::min(rmin, r), rmax = std::max(rmax, r);
    zmin = std::min(zmin, x.z()), zmax = std::max(zmax, x.z());
  }
  EXPECT_LE(rmax, R + 1e-9);
  EXPECT_GE(rmin, R - sag - 1e-9);
  EXPECT_NEAR(zmin, 0.0, 1e-12);
  EXPECT_NEAR(zmax, L, 1e-12);
  // Two open ends, consistent outward orientation (positive capped volume).
  auto loops = boundary_loops(s);
  ASSERT_EQ(loops.size(), 2u);
  const double V = signed_volume(capped(s, loops));
  const double exact = M_PI * R * R * L;
  std::printf("lofted volume %.5f vs cylinder %.5f (rel %.2e), radius in [%.5f, %.5f]\n", V, exact, V / exact - 1,
              rmin, rmax);
  // The 48-gon has area (n/2π)·sin(2π/n) = 0.99715 of the circle's; the
  // resampled 64-gon on it loses less than another 0.3 %.
  EXPECT_LT(V, exact);
  EXPECT_GT(V, 0.994 * exact);
  // Contours drawn in both directions and with different start points are
  // aligned: no twisted (long) axial edges.
  double longest = 0;
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) longest = std::max(longest, (s.points[t[k]] - s.points[t[(k + 1) % 3]]).norm());
  EXPECT_LT(longest, 0.5);
}

TEST(SimVascular, CaseInputLoftsLumenAndWall) {
  fs::path dir = fs::temp_directory_path() / "stentsim_sv_case";
  fs::create_directories(dir);
  auto cfg = ConfigMap::from_string("simvascular:\n  path: " + (kData / "straight_lad.pth").string() +
                                        "\n  lumen: " + (kData / "straight_lad_lumen.ctgr").string() +
                                        "\n  wall: " + (kData / "straight_lad_wall.ctgr").string() + "\n",
                                    dir / "case.yaml");
  SegmentationInput in = parse_segmentation_input(cfg);
  EXPECT_EQ(in.input_files().size(), 3u);
  Summary summary;
  run_segmentation_stage(in, dir / "lumen.vtp", dir / "wall.vtp", summary);
  MeshData lumen = read_vtp((dir / "lumen.vtp").string());
  MeshData wall = read_vtp((dir / "wall.vtp").string());
  EXPECT_GT(lumen.num_cells(), 1000u);
  EXPECT_GT(wall.num_cells(), 1000u);
  fs::remove_all(dir);
}

TEST(SimVascular, BadFilesNameFileAndElement) {
  std::string e = error_of([] { read_simvascular_contours(kData / "broken_unclosed.ctgr"); });
  EXPECT_NE(e.find("broken_unclosed.ctgr"), std::string::npos) << e;
  EXPECT_NE(e.find("not valid XML"), std::string::npos) << e;
  e = error_of([] { read_simvascular_contours(kData / "missing_attribute.ctgr"); });
  EXPECT_NE(e.find("missing_attribute.ctgr"), std::string::npos) << e;
  EXPECT_NE(e.find("<contour id=0>/<contour_points>/<point id=5>"), std::string::npos) << e;
  EXPECT_NE(e.find("`x`"), std::string::npos) << e;
  e = error_of([] { read_simvascular_path(kData / "straight_lad_lumen.ctgr"); });
  EXPECT_NE(e.find("no <path> element"), std::string::npos) << e;
  e = error_of([] { read_simvascular_path(kData / "nonexistent.pth"); });
  EXPECT_NE(e.find("not found"), std::string::npos) << e;
  // Case file: a wrong extension is named with the key.
  auto cfg = ConfigMap::from_string("simvascular:\n  path: a.ctgr\n  lumen: b.ctgr\n", "case.yaml");
  e = error_of([&] { parse_segmentation_input(cfg); });
  EXPECT_NE(e.find("path"), std::string::npos) << e;
  EXPECT_NE(e.find(".pth"), std::string::npos) << e;
}

TEST(SimVascular, MetreContoursAreReportedWhenTheCaseSaysMm) {
  // The same tube in metres (1.5 mm → 0.0015): its size says metres.
  SvPath p = read_simvascular_path(kData / "straight_lad.pth");
  TriSurface s = loft_contours(p, read_simvascular_contours(kData / "straight_lad_lumen.ctgr"), {}, "lumen");
  for (auto& x : s.points) x *= 1e-3;
  SurfaceReport rep;
  std::string e = error_of([&] { check_and_repair(s, SurfaceCheckOptions{}, "lumen.ctgr", rep); });
  EXPECT_NE(e.find("looks like it is in metres"), std::string::npos) << e;
}
