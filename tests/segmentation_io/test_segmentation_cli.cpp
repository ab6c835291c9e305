// `stentsim segmentation` through the binary with bad input (issue 3): every
// failure exits with code 2 and a message naming the file, the field and what
// was expected; a good phantom input runs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "tests/workflows/cli_runner.hpp"

namespace fs = std::filesystem;
using stentsim::testing::run_stentsim;

namespace {

class SegmentationCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("stentsim-segcli-" + std::to_string(::getpid()) + "-" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  // Writes `text` to dir/name and runs `stentsim segmentation` on it.
  stentsim::testing::CliResult segment(const std::string& name, const std::string& text) {
    stentsim::files::write_atomic(dir / name, text);
    return run_stentsim("segmentation " + (dir / name).string() + " --out " + (dir / "out").string());
  }
  void expect_failure(const stentsim::testing::CliResult& r, std::initializer_list<std::string> parts) {
    EXPECT_EQ(r.code, 2) << r.out;
    for (const auto& p : parts) EXPECT_NE(r.out.find(p), std::string::npos) << "missing '" << p << "' in:\n" << r.out;
    EXPECT_FALSE(fs::exists(dir / "out" / "lumen.vtp"));
  }
  fs::path dir;
};

TEST_F(SegmentationCli, BadInputNamesFileFieldAndExpectation) {
  const std::string d = dir.string();
  // The input file itself is missing.
  auto r = run_stentsim("segmentation " + d + "/nope.yaml --out " + d + "/out");
  expect_failure(r, {"nope.yaml", "not found"});

  // An unknown key in the input section: file, line, column and key.
  r = segment("typo.yaml", "input:\n  surface:\n    lumen: lumen.vtp\n    lumn_units: mm\n");
  expect_failure(r, {"typo.yaml:4:5", "input.surface.lumn_units", "unknown key"});

  // A lumen surface that does not exist: the field and the file.
  r = segment("missing_lumen.yaml", "input:\n  surface:\n    lumen: " + d + "/absent.stl\n");
  expect_failure(r, {"absent.stl"});

  // A label image with an extension no reader takes.
  r = segment("label.yaml", "input:\n  label_image:\n    file: " + d + "/labels.png\n");
  expect_failure(r, {"label.yaml", "file", "expected a NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr) or MetaImage"});

  // A SimVascular path given where the contours belong.
  r = segment("sv.yaml", "input:\n  simvascular:\n    path: a.pth\n    lumen: b.pth\n");
  expect_failure(r, {"sv.yaml", "lumen", "expected a SimVascular .ctgr file"});

  // Two kinds of input at once.
  r = segment("two.yaml", "input:\n  surface: {lumen: a.vtp}\n  label_image: {file: b.nii}\n");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("two.yaml"), std::string::npos) << r.out;

  // A label image file that is not an image.
  stentsim::files::write_atomic(dir / "fake.nrrd", "this is not NRRD\n");
  r = segment("fake.yaml", "input:\n  label_image:\n    file: " + d + "/fake.nrrd\n");
  expect_failure(r, {"fake.nrrd", "not a readable NRRD file"});
}

TEST_F(SegmentationCli, MetreSurfaceInAMillimetreCaseIsReported) {
  const std::string d = dir.string();
  auto r = run_stentsim("phantom --preset straight-healthy --out " + d + "/ph");
  ASSERT_EQ(r.code, 0) << r.out;
  // The same lumen, exported in metres.
  stentsim::MeshData lumen = stentsim::read_vtp((dir / "ph/lumen.vtp").string());
  for (auto& p : lumen.points) p *= 1e-3;
  stentsim::write_vtp((dir / "lumen_m.vtp").string(), lumen);
  r = segment("metres.yaml", "input:\n  surface:\n    lumen: " + d + "/lumen_m.vtp\n    units: mm\n");
  expect_failure(r, {"lumen_m.vtp", "metres", "units: m"});
  // Saying so makes it run.
  r = segment("metres_ok.yaml", "input:\n  surface:\n    lumen: " + d + "/lumen_m.vtp\n    units: m\n");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::exists(dir / "out" / "lumen.vtp"));
  EXPECT_TRUE(fs::exists(dir / "out" / "wall.vtp"));
  EXPECT_TRUE(fs::exists(dir / "out" / "summary.yaml"));
}

// `stentsim run` on patient cases whose input is a SimVascular .pth/.ctgr pair
// (the straight fixture) and a NRRD label image (a labelled cylinder with an
// oblique "space directions"): segmentation and centerline produce lumen.vtp,
// wall.vtp and centerline.vtp.
TEST_F(SegmentationCli, RunMakesLumenWallAndCenterlineFromSimVascularAndLabelImage) {
  const fs::path data = fs::path(STENTSIM_TEST_SOURCE_DIR) / "tests/segmentation_io/data";
  stentsim::files::write_atomic(dir / "sv.yaml", "name: sv\nscene: patient\ninput:\n  simvascular:\n    path: " +
                                                     (data / "straight_lad.pth").string() + "\n    lumen: " +
                                                     (data / "straight_lad_lumen.ctgr").string() + "\n    wall: " +
                                                     (data / "straight_lad_wall.ctgr").string() + "\n");
  // Lumen label 1 (r < 1.2 mm) and wall label 2 (r < 1.8 mm) along index axis k, 0.1 mm voxels.
  const int n[3] = {40, 40, 100};
  std::vector<unsigned char> v(std::size_t(n[0]) * n[1] * n[2], 0);
  for (int k = 5; k < 95; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const double r = 0.1 * std::hypot(i - 19.5, j - 19.5);
        v[std::size_t(i + n[0] * (j + n[1] * k))] = r < 1.2 ? 1 : (r < 1.8 ? 2 : 0);
      }
  {
    std::ofstream f(dir / "labels.nrrd", std::ios::binary);
    f << "NRRD0004\ntype: uint8\ndimension: 3\nspace: left-posterior-superior\nsizes: 40 40 100\n"
         "space directions: (0,0.1,0) (0,0,0.1) (0.1,0,0)\nspace origin: (5,6,7)\nencoding: raw\n\n";
    f.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size()));
  }
  stentsim::files::write_atomic(dir / "img.yaml", "name: img\nscene: patient\ninput:\n  label_image:\n    file: " +
                                                      (dir / "labels.nrrd").string() + "\n    wall_label: 2\n");
  for (const char* c : {"sv", "img"}) {
    SCOPED_TRACE(c);
    auto r = run_stentsim("run " + (dir / (std::string(c) + ".yaml")).string() + " --until centerline");
    ASSERT_EQ(r.code, 0) << r.out;
    const fs::path work = dir / (std::string(c) + ".work");
    for (const char* f : {"segmentation/lumen.vtp", "segmentation/wall.vtp", "centerline/centerline.vtp"})
      EXPECT_TRUE(fs::exists(work / f)) << f;
    const auto cl = stentsim::read_vtp((work / "centerline/centerline.vtp").string());
    ASSERT_GT(cl.points.size(), 10u);
    // The label image's vessel runs along world x (index k), from x = 5.5 to 14.4 mm.
    if (std::string(c) == "img")
      for (const auto& p : cl.points) {
        EXPECT_NEAR(p.y(), 6.0 + 1.95, 0.05);
        EXPECT_NEAR(p.z(), 7.0 + 1.95, 0.05);
      }
  }
}

}  // namespace
