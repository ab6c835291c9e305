#pragma once
// Which stages a case needs (DESIGN.md §3): a free-expansion scene has no
// artery, so no wall mesh or fibers are made, and no segmentation or
// centerline either unless it has an input to place its device along (the
// curved device).
#include <vector>

#include "pipeline/stage.hpp"
#include "workflows/case_config.hpp"

namespace stentsim::workflows {

/// The canonical stage names in pipeline order.
const std::vector<std::string>& all_stage_names();

/// The stages this case's scene needs, wired to their implementations.
std::vector<pipeline::Stage> stages_for(const CaseConfig& c);

}  // namespace stentsim::workflows
