#pragma once
// What a cohort run leaves beside cohort_summary.csv for people to read: one
// PNG per numeric QoI (value per case; failures and expected failures marked)
// and cohort_summary.md (a table per case and per-QoI statistics).
#include <filesystem>
#include <string>
#include <vector>

#include "workflows/cohort/cohort_runner.hpp"

namespace stentsim::workflows {

/// The QoI columns whose every non-empty cell is a number ("<stage>.<qoi> [unit]").
std::vector<std::string> numeric_qoi_columns(const CohortTable& t);

/// Writes <work_dir>/plot_<stage>.<qoi>.png for every numeric QoI column and
/// returns their paths. A case without a value (it failed before that stage)
/// is drawn as a cross on the bottom axis; failures are red, expected failures gold.
std::vector<std::filesystem::path> write_cohort_plots(const CohortConfig& c, const CohortTable& t);

/// Writes <work_dir>/cohort_summary.md: per-case table (status, failed stage,
/// wall time, QoIs) and min/median/max of every numeric QoI over the cases
/// that have it, with links to the plots.
void write_cohort_markdown(const CohortConfig& c, const CohortTable& t);

}  // namespace stentsim::workflows
