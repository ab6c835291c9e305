// `stentsim segmentation` through the binary with bad input (issue 3): every
// failure exits with code 2 and a message naming the file, the field and what
// was expected; a good phantom input runs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
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
// (the straight fixture), a NRRD label image (a labelled cylinder with an
// oblique "space directions") and a binary STL lumen (the straight-healthy
// phantom; the wall is synthesized): segmentation and centerline produce lumen.vtp,
// wall.vtp and centerline.vtp.
TEST_F(SegmentationCli, RunMakesLumenWallAndCenterlineFromSimVascularLabelImageAndStl) {
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
  // A binary STL of the straight-healthy phantom's lumen (triangle soup, no
  // shared vertices: the reader and the checks must weld it back into a tube).
  {
    auto ph = run_stentsim("phantom --preset straight-healthy --out " + (dir / "ph").string());
    ASSERT_EQ(ph.code, 0) << ph.out;
    const stentsim::MeshData m = stentsim::read_vtp((dir / "ph/lumen.vtp").string());
    std::ofstream f(dir / "lumen.stl", std::ios::binary);
    const std::string header(80, ' ');
    f.write(header.data(), 80);
    const auto count = std::uint32_t(m.num_cells());
    f.write(reinterpret_cast<const char*>(&count), 4);
    for (std::size_t c = 0; c < m.num_cells(); ++c) {
      const auto nodes = m.cell(c);
      ASSERT_EQ(nodes.size(), 3u);
      const Eigen::Vector3d a = m.points[std::size_t(nodes[0])], b = m.points[std::size_t(nodes[1])],
                            d = m.points[std::size_t(nodes[2])];
      const Eigen::Vector3d nrm = (b - a).cross(d - a).normalized();
      float rec[12];
      for (int k = 0; k < 3; ++k) rec[k] = float(nrm[k]), rec[3 + k] = float(a[k]), rec[6 + k] = float(b[k]),
                                  rec[9 + k] = float(d[k]);
      f.write(reinterpret_cast<const char*>(rec), sizeof rec);
      const std::uint16_t attr = 0;
      f.write(reinterpret_cast<const char*>(&attr), 2);
    }
  }
  stentsim::files::write_atomic(dir / "stl.yaml", "name: stl\nscene: patient\ninput:\n  surface:\n    lumen: " +
                                                      (dir / "lumen.stl").string() + "\n    units: mm\n");
  for (const char* c : {"sv", "img", "stl"}) {
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
    // The STL phantom is a straight tube of radius 1.25 mm, 20 mm long: the
    // inscribed radius within 3 % of it away from the ends (issue 3's bound).
    if (std::string(c) == "stl") {
      const auto& S = cl.point_data.at("Abscissas").values;
      const auto& R = cl.point_data.at("MaximumInscribedSphereRadius").values;
      ASSERT_GT(S.back(), 17.0);
      int inner = 0;
      for (std::size_t i = 0; i < S.size(); ++i)
        if (S[i] > 2.5 && S[i] < S.back() - 2.5) {
          EXPECT_NEAR(R[i], 1.25, 0.03 * 1.25) << "at s = " << S[i];
          ++inner;
        }
      EXPECT_GT(inner, 10);
    }
  }
}

}  // namespace
