#include "workflows/case_sections.hpp"

namespace stentsim::workflows {

void validate_stage_sections(const CaseConfig& c, ConfigMap& top) {
  if (c.scene != Scene::patient && top.has("input"))
    top.fail("input", "a " + std::string(to_string(c.scene)) + " scene has no artery input; remove this section");
  auto input = top.map("input");
  auto device = top.map("device");
  (void)input;
  (void)device;
}

}  // namespace stentsim::workflows
