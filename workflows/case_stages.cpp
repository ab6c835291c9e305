#include "workflows/case_stages.hpp"

#include "common/config.hpp"

namespace stentsim::workflows {

const std::vector<std::string>& all_stage_names() {
  static const std::vector<std::string> names = {"segmentation", "centerline", "placement", "balloon", "stent",
                                                 "mesh",         "fibers",     "solve",     "report"};
  return names;
}

std::vector<pipeline::Stage> stages_for(const CaseConfig& c) {
  std::vector<pipeline::Stage> stages;
  return stages;
}

}  // namespace stentsim::workflows
