#include "workflows/case_sections.hpp"

#include "segmentation_io/centerline.hpp"
#include "segmentation_io/segmentation_stage.hpp"

namespace stentsim::workflows {

void validate_stage_sections(const CaseConfig& c, ConfigMap& top) {
  if (c.scene != Scene::patient) {
    if (top.has("input"))
      top.fail("input", "a " + std::string(to_string(c.scene)) + " scene has no artery input; remove this section");
    if (top.has("centerline"))
      top.fail("centerline", "a " + std::string(to_string(c.scene)) + " scene has no lumen centerline; remove this section");
  } else {
    if (!top.has("input")) top.fail("input", "a patient scene needs an input section (e.g. input: {phantom: {preset: case2-rca}})");
    auto input = top.map("input");
    segmentation::parse_segmentation_input(input);
    auto centerline = top.map("centerline");
    segmentation::parse_centerline_options(centerline);
  }
  // Device sections are validated by the device stages' parsers once they are wired.
  auto device = top.map("device");
  (void)device;
}

}  // namespace stentsim::workflows
