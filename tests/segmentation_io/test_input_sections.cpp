// The case's `input:` section for the new sources (simvascular, label_image,
// tree): errors name the file, the line and the key.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "common/config.hpp"
#include "common/error.hpp"
#include "segmentation_io/segmentation_stage.hpp"

using namespace stentsim;
using namespace stentsim::segmentation;

namespace {
std::string error_of(const std::string& yaml) {
  auto cfg = ConfigMap::from_string(yaml, "case.yaml");
  try {
    parse_segmentation_input(cfg);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(InputSections, TreeNeedsExactlyOneOfToOrLongestPath) {
  std::string e = error_of("tree:\n  file: t.stl\n  from: [0, 0, 0]\n");
  EXPECT_NE(e.find("case.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("longest_path_from_inlet"), std::string::npos) << e;
  e = error_of("tree:\n  file: t.stl\n  from: [0, 0, 0]\n  to: [1, 2, 3]\n  longest_path_from_inlet: true\n");
  EXPECT_NE(e.find("to"), std::string::npos) << e;
  e = error_of("tree:\n  file: t.stl\n  from: [0, 0]\n  to: [1, 2, 3]\n");
  EXPECT_NE(e.find("from"), std::string::npos) << e;
  e = error_of("tree:\n  file: t.stl\n  from: [0, 0, 0]\n  to: [1, 2, 3]\n  roi_length: -2 mm\n");
  EXPECT_NE(e.find("roi_length"), std::string::npos) << e;
  auto cfg = ConfigMap::from_string("tree:\n  file: t.stl\n  from: [0, 0, 0]\n  to: [1, 2, 3]\n  roi_length: 2 cm\n",
                                    "case.yaml");
  SegmentationInput in = parse_segmentation_input(cfg);
  const auto& t = std::get<TreeInput>(in.source);
  ASSERT_TRUE(t.roi_length);
  EXPECT_DOUBLE_EQ(*t.roi_length, 20.0);
  EXPECT_DOUBLE_EQ(t.to->z(), 3.0);
}

TEST(InputSections, LabelImageKeys) {
  std::string e = error_of("label_image:\n  file: seg.png\n");
  EXPECT_NE(e.find("file"), std::string::npos) << e;
  EXPECT_NE(e.find(".nii"), std::string::npos) << e;
  e = error_of("label_image:\n  file: seg.nii.gz\n  lumen_label: 2\n  wall_label: 2\n");
  EXPECT_NE(e.find("wall_label"), std::string::npos) << e;
  e = error_of("label_image:\n  file: seg.nii.gz\n  lumen_lable: 2\n");
  EXPECT_NE(e.find("lumen_lable"), std::string::npos) << e;
}

TEST(InputSections, ExactlyOneSource) {
  std::string e = error_of("label_image:\n  file: seg.nii\nsimvascular:\n  path: p.pth\n  lumen: l.ctgr\n");
  EXPECT_NE(e.find("exactly one of"), std::string::npos) << e;
  EXPECT_NE(e.find("tree"), std::string::npos) << e;
}
