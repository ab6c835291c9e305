#pragma once
// The case's report stage: report/report.md and report/report.html (one
// self-contained file) from the solve stage's summary and history, the
// manifest and the paper's numbers (workflows/report/report.hpp).
#include "pipeline/stage.hpp"
#include "workflows/case_config.hpp"

namespace stentsim::workflows {

pipeline::Stage report_stage(const CaseConfig& c);

}  // namespace stentsim::workflows
