// The case's `input.tree:` on the XCAT coronary tree (../shared/data): the
// longest path from an inlet and a region of interest around the stenosis,
// through the whole segmentation stage (lumen.vtp, wall.vtp).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include <yaml-cpp/yaml.h>

#include "common/config.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "segmentation_io/segmentation_stage.hpp"
#include "segmentation_io/triangle_surface.hpp"

using namespace stentsim;
using namespace stentsim::segmentation;
namespace fs = std::filesystem;

TEST(TreeInput, LongestPathFromInletWithRegionOfInterest) {
  const char* env = std::getenv("STENTSIM_SHARED_DIR");
  fs::path f = (env ? fs::path(env) : fs::path("../shared")) / "data" / "xcat_coronary_tree.stl";
  if (!fs::exists(f)) GTEST_SKIP() << "XCAT tree not found at " << f;
  fs::path dir = fs::temp_directory_path() / "stentsim_tree_input";
  fs::create_directories(dir);
  // The inlet of the right-coronary-like vessel used by test_tree_branch.
  auto cfg = ConfigMap::from_string("tree:\n  file: " + f.string() +
                                        "\n  from: [-33.07, 19.97, -22.39]\n  longest_path_from_inlet: true\n"
                                        "  roi_length: 15 mm\n",
                                    dir / "case.yaml");
  SegmentationInput in = parse_segmentation_input(cfg);
  Summary summary;
  run_segmentation_stage(in, dir / "lumen.vtp", dir / "wall.vtp", summary);
  TriSurface lumen = surface_from_mesh(read_vtp((dir / "lumen.vtp").string()), "lumen");
  EXPECT_EQ(boundary_loops(lumen).size(), 2u);
  summary.write(dir / "summary.yaml");
  YAML::Node q = YAML::LoadFile((dir / "summary.yaml").string())["qoi"];
  const double length = q["tree_segment_length"]["value"].as<double>();
  const double s0 = q["roi_start_abscissa"]["value"].as<double>(), s1 = q["roi_end_abscissa"]["value"].as<double>();
  std::printf("longest path from the inlet: %.2f mm; region of interest %.2f to %.2f mm\n", length, s0, s1);
  EXPECT_GT(length, 60.0);  // the longest vessel, not a side branch
  EXPECT_NEAR(s1 - s0, 15.0, 1e-9);
  EXPECT_GE(s0, 0.0);
  EXPECT_LE(s1, length);
  // The clipped lumen spans about the region's length along its axis.
  double diag = bounding_box_diagonal(lumen);
  EXPECT_GT(diag, 10.0);
  EXPECT_LT(diag, 25.0);
  fs::remove_all(dir);
}
