// The stentsim binary end to end: init, run, status, a second run that
// skips everything, and exit codes for bad input.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/files.hpp"
#include "common/summary.hpp"
#include "common/mesh_data.hpp"
#include "segmentation_io/surface_input.hpp"
#include "segmentation_io/triangle_surface.hpp"
#include "tests/workflows/cli_runner.hpp"

namespace fs = std::filesystem;

namespace {

using Result = stentsim::testing::CliResult;
Result sh(const std::string& args) { return stentsim::testing::run_stentsim(args); }

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("stentsim-cli-" + std::to_string(::getpid()) + "-" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

TEST_F(Cli, BadInputExitsWithTwoAndNamesTheProblem) {
  auto r = sh("run " + (dir / "missing.yaml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("missing.yaml: file not found"), std::string::npos) << r.out;
  stentsim::files::write_atomic(dir / "bad.yaml", "scene: patient\nsimulation:\n  presure_max: 1 MPa\n");
  r = sh("run " + (dir / "bad.yaml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("bad.yaml:3:3: simulation.presure_max: unknown key"), std::string::npos) << r.out;
  r = sh("run " + (dir / "bad.yaml").string() + " --jobs 0");
  EXPECT_EQ(r.code, 2);
  r = sh("frobnicate");
  EXPECT_EQ(r.code, 2);
}

TEST_F(Cli, InitRunStatusAndSecondRunSkipsEveryStage) {
  for (const char* scene : {"free-expansion", "generic-artery", "patient"}) {
    auto r = sh("init " + dir.string() + " --scene " + scene);
    ASSERT_EQ(r.code, 0) << r.out;
    const std::string c = (dir / (std::string(scene) + ".yaml")).string();
    // The bundled cases' solves take from half an hour (free expansion) to hours: stop before them
    // (test_workflows_solve_stage runs a small free expansion through solve and report).
    const std::string until = std::string(scene) == "free-expansion" ? " --until stent" : " --until fibers";
    r = sh("run " + c + " --dry-run");
    EXPECT_EQ(r.code, 0) << r.out;
    r = sh("run " + c + until);
    ASSERT_EQ(r.code, 0) << r.out;
    r = sh("run " + c + until);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("\n0 ran, "), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("run   "), std::string::npos) << r.out;
    r = sh("status " + c);
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out.find("stale"), std::string::npos) << r.out;
    // init never overwrites.
    r = sh("init " + dir.string() + " --scene " + scene);
    EXPECT_EQ(r.code, 2) << r.out;
  }
}

// The case's `stenosis:` section is the one rule of the centerline stage and
// the placement: case2-rca's 20 % lesion is listed in the centerline summary;
// with threshold_percent 30 there is no lesion, the placement says so and
// names device.placement.site_abscissa, and giving it clears the error.
TEST_F(Cli, StenosisSectionReachesCenterlineAndPlacement) {
  const auto c = dir / "case.yaml";
  const std::string base = "name: st\nscene: patient\ninput: {phantom: {preset: case2-rca}}\n";
  stentsim::files::write_atomic(c, base);
  auto r = sh("run " + c.string() + " --until placement");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto summary = stentsim::Summary::read(dir / "case.work" / "centerline" / "summary.yaml");
  ASSERT_EQ(std::get<double>(summary.qois().at("lesion_count").value), 1.0) << r.out;
  EXPECT_NEAR(std::get<double>(summary.qois().at("lesion_1_percent_diameter").value), 20.0, 2.0);
  stentsim::files::write_atomic(c, base + "stenosis: {threshold_percent: 30}\n");
  r = sh("run " + c.string() + " --until placement");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("no lesion deeper than 30 %"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("device.placement.site_abscissa"), std::string::npos) << r.out;
  stentsim::files::write_atomic(c, base + "stenosis: {threshold_percent: 30}\ndevice: {placement: {site_abscissa: 12 mm}}\n");
  r = sh("run " + c.string() + " --until placement");
  EXPECT_EQ(r.code, 0) << r.out;
  stentsim::files::write_atomic(c, "scene: free-expansion\nstenosis: {threshold_percent: 30}\n");
  r = sh("run " + c.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("stenosis: a free-expansion scene without an input has no lumen"), std::string::npos) << r.out;
}

TEST_F(Cli, ForceUntilAndOnlyParseInEveryForm) {
  ASSERT_EQ(sh("init " + dir.string() + " --scene generic-artery").code, 0);
  const std::string c = (dir / "generic-artery.yaml").string();
  // --until fibers: mesh and fibers only (the generic artery's solve takes minutes).
  const std::string until = " --until fibers";
  ASSERT_EQ(sh("run " + c + until).code, 0);
  auto ran = [](const Result& r) { return r.out.substr(r.out.rfind('\n', r.out.size() - 2) + 1); };
  for (const std::string& args : {"run " + c + " --force" + until, "run --force " + c + until}) {
    auto r = sh(args);
    ASSERT_EQ(r.code, 0) << args << "\n" << r.out;
    EXPECT_EQ(ran(r).rfind("2 ran, 0 up to date", 0), 0u) << args << "\n" << r.out;
  }
  for (const std::string& args : {"run " + c + " --force mesh" + until, "run --force mesh " + c + until,
                                  "run --force=mesh " + c + until}) {
    auto r = sh(args);
    ASSERT_EQ(r.code, 0) << args << "\n" << r.out;
    EXPECT_EQ(ran(r).rfind("1 ran, 1 up to date", 0), 0u) << args << "\n" << r.out;
  }
  auto r = sh("run " + c + " --force nosuchstage");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("no stage named 'nosuchstage'"), std::string::npos) << r.out;
  r = sh("run " + c + " --until=");
  EXPECT_EQ(r.code, 2) << r.out;
  r = sh("run " + c + " --until mesh --only mesh");
  EXPECT_EQ(r.code, 2) << r.out;
  r = sh("run " + c + " --dry-run --force");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("run   mesh          forced"), std::string::npos) << r.out;
}

TEST_F(Cli, EveryPreprocessingStageRunsAsAToolOfItsOwn) {
  const std::string d = dir.string();
  auto r = sh("phantom --preset case2-rca --out " + d + "/ph");
  ASSERT_EQ(r.code, 0) << r.out;
  r = sh("centerline --lumen " + d + "/ph/lumen.vtp --out " + d + "/cl/centerline.vtp --true-centerline " + d +
         "/ph/centerline_true.vtp");
  ASSERT_EQ(r.code, 0) << r.out;
  r = sh("place --centerline " + d + "/cl/centerline.vtp --lumen " + d + "/ph/lumen.vtp --out " + d + "/pl");
  ASSERT_EQ(r.code, 0) << r.out;
  r = sh("balloon --placement " + d + "/pl/placement.yaml --out " + d + "/b/balloon.vtu");
  ASSERT_EQ(r.code, 0) << r.out;
  stentsim::files::write_atomic(dir / "dev.yaml", "stent: {rings: 11}\n");
  r = sh("stent --device " + d + "/dev.yaml --out " + d + "/s/stent.vtu");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(stentsim::files::read_text(dir / "s/summary.yaml").find("value: 588"), std::string::npos);
  for (const char* f : {"ph/lumen.vtp", "cl/centerline.vtp", "cl/summary.yaml", "pl/placement.yaml",
                        "pl/balloon_centerline.vtp", "b/balloon.vtu", "s/stent.vtu"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  stentsim::files::write_atomic(dir / "bad.yaml", "stent: {rngs: 11}\n");
  r = sh("stent --device " + d + "/bad.yaml --out " + d + "/x.vtu");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("bad.yaml:1:9: stent.rngs: unknown key"), std::string::npos) << r.out;
  r = sh("phantom --preset nonesuch --out " + d + "/x");
  EXPECT_EQ(r.code, 2);
}

// The stand-alone centerline tool reads the lumen by its extension and runs the case
// path's surface checks: a damaged file is exit 2 naming it, never a centerline of garbage.
TEST_F(Cli, StandAloneCenterlineChecksItsSurfaceAsTheCasePathDoes) {
  const std::string d = dir.string();
  // A binary STL of one triangle with a NaN coordinate (it once reached CGAL through this tool).
  std::string stl(80, ' ');
  const std::uint32_t one = 1;
  stl.append(reinterpret_cast<const char*>(&one), 4);
  const float record[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, std::numeric_limits<float>::quiet_NaN(), 0};
  stl.append(reinterpret_cast<const char*>(record), sizeof record);
  stl.append(2, '\0');
  stentsim::files::write_atomic(dir / "nan.stl", stl);
  auto r = sh("centerline --lumen " + d + "/nan.stl --out " + d + "/c1/centerline.vtp");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("nan.stl"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not a finite number"), std::string::npos) << r.out;
  stentsim::files::write_atomic(dir / "lumen.stl", std::string("solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n"
                                                               "  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\n"
                                                               "endsolid x\n"));
  r = sh("centerline --lumen " + d + "/lumen.stl --out " + d + "/c2/centerline.vtp");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("lumen.stl"), std::string::npos) << r.out;  // read as STL, then refused by the checks
  EXPECT_EQ(r.out.find("XML"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "c2/centerline.vtp"));
  r = sh("centerline --lumen " + d + "/lumen.stl --units parsecs --out " + d + "/c3/centerline.vtp");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--units"), std::string::npos) << r.out;  // the option and its values named
  EXPECT_NE(r.out.find("mm"), std::string::npos) << r.out;
}

// The units rule and the spacing bounds hold for the stand-alone tool as for a case: a
// phantom in mm declared in cm or um is refused with the units it looks like, and nothing
// is written.
TEST_F(Cli, StandAloneCenterlineRefusesMisdeclaredUnitsAndSpacing) {
  const std::string d = dir.string();
  auto r = sh("phantom --preset case2-rca --out " + d + "/ph");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* units : {"cm", "um"}) {
    r = sh("centerline --lumen " + d + "/ph/lumen.vtp --units " + units + " --out " + d + "/u/centerline.vtp");
    EXPECT_EQ(r.code, 2) << units << ": " << r.out;
    EXPECT_NE(r.out.find("lumen.vtp"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("set --units mm"), std::string::npos) << units << ": " << r.out;
    EXPECT_FALSE(fs::exists(dir / "u/centerline.vtp"));
  }
  for (const char* spacing : {"1e-9", "0", "50"}) {
    r = sh("centerline --lumen " + d + "/ph/lumen.vtp --spacing " + spacing + " --out " + d + "/s/centerline.vtp");
    EXPECT_EQ(r.code, 2) << spacing << ": " << r.out;
    EXPECT_NE(r.out.find("--spacing"), std::string::npos) << r.out;
  }
  EXPECT_FALSE(fs::exists(dir / "s/centerline.vtp"));
}

// A lumen damaged in ways a reader cannot see (one vertex's coordinate with its sign flipped, a
// triangle pointing at a wrong but valid vertex, a vertex shifted far off) is refused by the
// stand-alone centerline tool's surface checks, exit 2 naming the file, and no centerline of
// the damage (once: a 99 % "stenosis") is written.
TEST_F(Cli, StandAloneCenterlineRefusesACorruptedSurface) {
  const std::string d = dir.string();
  auto r = sh("phantom --preset case2-rca --out " + d + "/ph");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto lumen = stentsim::segmentation::read_surface_file(dir / "ph/lumen.vtp");
  auto write_obj = [&](const std::string& name, const stentsim::segmentation::TriSurface& s) {
    std::ofstream f(dir / name);
    f.precision(17);
    for (const auto& p : s.points) f << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
    for (const auto& t : s.triangles) f << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  };
  write_obj("intact.obj", lumen);
  r = sh("centerline --lumen " + d + "/intact.obj --out " + d + "/intact/centerline.vtp");
  ASSERT_EQ(r.code, 0) << r.out;
  // A vertex in the middle of the vessel.
  std::size_t mid = 0;
  const Eigen::Vector3d centre = (lumen.points.front() + lumen.points.back()) / 2;
  for (std::size_t i = 0; i < lumen.points.size(); ++i)
    if ((lumen.points[i] - centre).norm() < (lumen.points[mid] - centre).norm()) mid = i;
  auto flipped = lumen, wrong_index = lumen, shifted = lumen;
  flipped.points[mid].x() = -flipped.points[mid].x();
  wrong_index.triangles[wrong_index.triangles.size() / 2][0] = 0;
  shifted.points[mid] += Eigen::Vector3d(3.0, -2.0, 1.0);
  write_obj("flipped.obj", flipped);
  write_obj("wrong_index.obj", wrong_index);
  write_obj("shifted.obj", shifted);
  // The sign flip and the wrong index fold the surface through itself.
  for (const char* name : {"flipped", "wrong_index"}) {
    r = sh("centerline --lumen " + d + "/" + name + ".obj --out " + d + "/" + name + "/centerline.vtp");
    EXPECT_EQ(r.code, 2) << name << ": " << r.out;
    EXPECT_NE(r.out.find(std::string(name) + ".obj: the surface intersects itself"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / name / "centerline.vtp")) << name;
  }
  // The shifted vertex makes a spike out of the lumen that folds nothing: a valid surface, whose
  // centerline and lesion stay those of the intact vessel (the inscribed spheres do not enter a
  // spike), not a "stenosis" of the damage.
  r = sh("centerline --lumen " + d + "/shifted.obj --out " + d + "/shifted/centerline.vtp");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto intact = stentsim::Summary::read(dir / "intact/summary.yaml"), spiked = stentsim::Summary::read(dir / "shifted/summary.yaml");
  for (const char* key : {"lesion_1_min_radius", "lesion_1_percent_diameter", "centerline_length"}) {
    const double a = std::get<double>(intact.qois().at(key).value), b = std::get<double>(spiked.qois().at(key).value);
    EXPECT_NEAR(b, a, 0.01 * a) << key;
  }
}

// `mesh` and `place` take lumen.vtp (and wall.vtp) as files and give them the case path's
// surface checks and units rule, repairs off: a damaged, holed, mis-scaled or swapped surface is refused
// (exit 2, the file named, what mends it said) before gmsh or the placement sees it, and
// nothing is written. The intact phantom passes (the other mesh and place tests).
TEST_F(Cli, StandAloneMeshAndPlaceRunTheSurfaceChecks) {
  namespace seg = stentsim::segmentation;
  const std::string d = dir.string();
  auto r = sh("phantom --preset case2-rca --out " + d + "/ph");
  ASSERT_EQ(r.code, 0) << r.out;
  const seg::TriSurface lumen = seg::read_surface_file(dir / "ph/lumen.vtp");
  auto write = [&](const std::string& name, const seg::TriSurface& s) {
    stentsim::write_vtp((dir / name).string(), seg::mesh_from_surface(s));
    return d + "/" + name;
  };
  std::size_t mid = 0;  // a vertex in the middle of the vessel
  const Eigen::Vector3d centre = (lumen.points.front() + lumen.points.back()) / 2;
  for (std::size_t i = 0; i < lumen.points.size(); ++i)
    if ((lumen.points[i] - centre).norm() < (lumen.points[mid] - centre).norm()) mid = i;
  auto flipped = lumen, holed = lumen, in_um = lumen, in_cm = lumen;
  flipped.points[mid].x() = -flipped.points[mid].x();
  holed.triangles.erase(holed.triangles.begin() + long(holed.triangles.size() / 2));
  for (auto& p : in_um.points) p *= 1000.0;  // outside the size window
  for (auto& p : in_cm.points) p *= 0.1;     // inside it: the reference-diameter rule
  const std::string wall = d + "/ph/wall.vtp", cl = d + "/ph/centerline_true.vtp";
  fs::copy_file(dir / "ph/lumen.vtp", dir / "lumen.stl");
  struct Bad {
    std::string lumen, wall, says;
  };
  const std::vector<Bad> bad{
      {write("flipped.vtp", flipped), wall, "flipped.vtp: the surface intersects itself"},
      {write("holed.vtp", holed), wall, "(stentsim mesh does not repair surfaces)"},
      {write("in_um.vtp", in_um), wall, "set input.surface.units: um"},
      {write("in_cm.vtp", in_cm), wall, "in_cm.vtp: the lumen's reference diameter is 0.1"},
      {d + "/lumen.stl", wall, "lumen.stl: stentsim mesh reads VTP surfaces"},
      {wall, d + "/ph/lumen.vtp", "lie outside the wall " + d + "/ph/lumen.vtp"},
      {d + "/ph/lumen.vtp", d + "/flipped.vtp", "flipped.vtp: the surface intersects itself"}};
  for (const auto& b : bad) {
    r = sh("mesh --lumen " + b.lumen + " --wall " + b.wall + " --centerline " + cl + " --out " + d + "/mesh");
    EXPECT_EQ(r.code, 2) << b.lumen << ": " << r.out;
    EXPECT_NE(r.out.find(b.says), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("stentsim mesh takes surfaces in mm as `stentsim segmentation` writes them"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "mesh")) << b.lumen;
  }
  r = sh("place --centerline " + cl + " --lumen " + d + "/flipped.vtp --out " + d + "/pl");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("flipped.vtp: the surface intersects itself"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("stentsim place takes surfaces in mm"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "pl/placement.yaml"));
}

TEST_F(Cli, SolveRunsASceneAndRejectsBadOnes) {
  const std::string scene = std::string(STENTSIM_TEST_SOURCE_DIR) + "/examples/tube_inflation.yaml";
  auto r = sh("solve " + scene + " --out " + dir.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::exists(dir / "results.pvd"));
  const auto summary = stentsim::files::read_text(dir / "summary.yaml");
  EXPECT_NE(summary.find("inner_radius_at_pmax"), std::string::npos) << summary;
  r = sh("solve " + (dir / "missing.yaml").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("missing.yaml"), std::string::npos) << r.out;
}

}  // namespace
