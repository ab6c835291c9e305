#pragma once
// Validation of the case sections that belong to preprocessing stages
// (input, device): each is handed to its stage's own parser.
#include "common/config.hpp"
#include "workflows/case_config.hpp"

namespace stentsim::workflows {

/// Parses (and so validates) the input and device sections the scene needs.
void validate_stage_sections(const CaseConfig& c, ConfigMap& top);

}  // namespace stentsim::workflows
