#include "workflows/case_sections.hpp"

#include "segmentation_io/centerline.hpp"
#include "device_gen/stages.hpp"
#include "segmentation_io/segmentation_stage.hpp"

namespace stentsim::workflows {

void validate_stage_sections(const CaseConfig& c, ConfigMap& top) {
  if (c.scene == Scene::generic_artery && top.has("input"))
    top.fail("input", "a generic-artery scene has no artery input (its artery is the paper's straight tube); remove this section");
  if (!c.placed) {
    if (top.has("centerline"))
      top.fail("centerline", c.scene == Scene::free_expansion
                                 ? "a free-expansion scene without an input has no lumen centerline; remove this section, or add "
                                   "an input: to place the device along a vessel (the curved device)"
                                 : "a generic-artery scene has no lumen centerline; remove this section");
  } else {
    if (!top.has("input")) top.fail("input", "a patient scene needs an input section (e.g. input: {phantom: {preset: case2-rca}})");
    auto input = top.map("input");
    segmentation::parse_segmentation_input(input);
    auto centerline = top.map("centerline");
    segmentation::parse_centerline_options(centerline);
  }
  auto device = top.map("device");
  auto balloon = device.map("balloon");
  device_gen::parse_balloon_design(balloon);
  auto stent = device.map("stent");
  device_gen::parse_stent_design(stent);
  if (c.placed) {
    auto placement = device.map("placement");
    device_gen::parse_placement_params(placement);
  } else if (device.has("placement")) {
    device.fail("placement", c.scene == Scene::free_expansion
                                 ? "a free expansion without an input is straight; remove this section, or add an input: to "
                                   "place the device along a vessel (the curved device)"
                                 : "a generic-artery scene's device is straight; remove this section");
  }
  device.finish();
}

}  // namespace stentsim::workflows
