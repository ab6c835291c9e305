// Real segmented vessels through `stentsim run` to the fibers stage with a
// case that holds nothing but name, scene and input (validation: minutes
// per vessel). Each: every stage passes, the lesion found is where this
// version found it (a regression reference: the datasets carry no stenosis
// annotation), the synthesized wall is outside the lumen, the mesh meets its
// quality bounds and stays within 2x of case2-rca's 6,200 tet10 per mm.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "common/files.hpp"
#include "common/summary.hpp"
#include "tests/workflows/cli_runner.hpp"

namespace fs = std::filesystem;

namespace {

double qoi(const fs::path& summary, const std::string& key) {
  const auto s = stentsim::Summary::read(summary);
  const auto it = s.qois().find(key);
  if (it == s.qois().end()) ADD_FAILURE() << summary << ": no " << key;
  return it == s.qois().end() ? NAN : std::get<double>(it->second.value);
}

struct Vessel {
  std::string name, input;          // the case's input: section (one line of YAML flow)
  double lesion_abscissa, lesion_percent;  // along the extracted segment, mm; percent diameter
};

void run_vessel(const Vessel& v) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim-real-" + v.name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path c = dir / (v.name + ".yaml");
  stentsim::files::write_atomic(c, "name: " + v.name + "\nscene: patient\ninput: " + v.input + "\n");
  const auto r = stentsim::testing::run_stentsim("run " + c.string() + " --until fibers");
  std::printf("%s\n", r.out.c_str());
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path w = dir / (v.name + ".work");
  const fs::path seg = w / "segmentation" / "summary.yaml", mesh = w / "mesh" / "summary.yaml";
  // The lesion the region of interest is centred on, against the recorded one
  // (within one reference diameter and 10 points).
  const double d_ref = qoi(seg, "lumen_reference_diameter");
  EXPECT_NEAR(qoi(seg, "roi_stenosis_abscissa"), v.lesion_abscissa, d_ref);
  EXPECT_NEAR(qoi(seg, "roi_stenosis_percent_diameter"), v.lesion_percent, 10.0);
  EXPECT_GE(d_ref, 1.5);
  EXPECT_LE(d_ref, 8.0);
  // The synthesized wall: outside the lumen by at least half its thickness.
  EXPECT_GE(qoi(seg, "wall_min_clearance_ratio"), 0.5);
  // The mesh's bounds (mesh.min_scaled_jacobian, mesh.max_aspect_ratio) and size.
  EXPECT_GE(qoi(mesh, "min_scaled_jacobian"), 0.05);
  EXPECT_LE(qoi(mesh, "max_aspect_ratio"), 50.0);
  const double length = qoi(w / "centerline" / "summary.yaml", "centerline_length");
  const double per_mm = qoi(mesh, "artery_elements") / length;
  std::printf("%s: %.0f tet10 per mm over %.1f mm, D_ref %.2f mm, lesion at %.2f mm (%.1f %%)\n", v.name.c_str(), per_mm,
              length, d_ref, qoi(seg, "roi_stenosis_abscissa"), qoi(seg, "roi_stenosis_percent_diameter"));
  EXPECT_LT(per_mm, 2 * 6200.0);
  EXPECT_TRUE(fs::exists(w / "fibers" / "fibers.vtu"));
  fs::remove_all(dir);
}

}  // namespace

// A patient coronary tree from X-ray angiography (dfemtoolz, GPL-3.0;
// tests/data/third_party/dfemtoolz_coronary_tree): closed, six outlets.
TEST(RealVessels, DfemtoolzCoronaryTreeLongestPathFromTheInlet) {
  const fs::path f = fs::path(STENTSIM_TEST_SOURCE_DIR) / "tests/data/third_party/dfemtoolz_coronary_tree/coronary_tree.stl";
  ASSERT_TRUE(fs::exists(f)) << f;
  run_vessel({"dfemtoolz", "{tree: {file: " + f.string() +
                               ", from: [27.695, -40.429, 101.090], longest_path_from_inlet: true, roi_length: 20 mm}}",
              71.36, 27.1});
}

// The XCAT coronary tree (../shared/data): the longest path from the right
// coronary inlet, its region of interest named by its length.
TEST(RealVessels, XcatTreeLongestPathFromTheInlet) {
  const char* env = std::getenv("STENTSIM_SHARED_DIR");
  const fs::path f = (env ? fs::path(env) : fs::path("../shared")) / "data" / "xcat_coronary_tree.stl";
  if (!fs::exists(f)) {
    if (env) FAIL() << "XCAT tree not found at " << f << " (STENTSIM_SHARED_DIR is set)";
    GTEST_SKIP() << "XCAT tree not found at " << f;
  }
  run_vessel({"xcat", "{tree: {file: " + f.string() +
                          ", from: [-33.07, 19.97, -22.39], longest_path_from_inlet: true, roi_length: 20 mm}}",
              14.30, 37.3});
}
