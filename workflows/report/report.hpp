#pragma once
// The case pipeline's `report` stage: what a person reads after a run. One
// Markdown and one self-contained HTML file with the same content (the case,
// the run's cost, the solve's QoIs, the comparison with the paper's numbers,
// figures, where the 3-D frames are), plus the figures as PNG and SVG files.
// Reads only files: manifest.yaml, the stages' summary.yaml, solve/history.csv
// and solve/results.pvd (DESIGN.md §6: never logs).
#include <filesystem>
#include <string>
#include <vector>

#include "common/summary.hpp"

namespace stentsim::workflows::report {

struct ReportInput {
  std::string case_name;            // the case's name
  std::string scene;                // "free-expansion", "generic-artery", "patient"
  std::filesystem::path case_file;  // absolute
  std::filesystem::path work_dir;   // holds manifest.yaml and <stage>/summary.yaml of every earlier stage
  std::filesystem::path solve_dir;  // holds summary.yaml, history.csv, results.pvd (+ results/*.vtu)
  std::string targets_key;          // "free_expansion_straight" | "free_expansion_curved" | "generic_artery_case1" | "patient_case2" | "" (no paper numbers)
  double pressure_max = 0;          // MPa, the case's inflation pressure
  std::vector<std::string> stages;  // the case's stages in pipeline order (the run table's rows)
};

/// Writes report.md and report.html (one self-contained file, images inline as base64 data: URIs)
/// and the figures' PNG/SVG files into `figure_dir`; adds its own entries (e.g. targets_passed, targets_failed,
/// targets_judged) to `summary`. Throws InputError naming the file when an input is missing or malformed.
void write_report(const ReportInput& in, const std::filesystem::path& md, const std::filesystem::path& html,
                  const std::filesystem::path& figure_dir, Summary& summary);

}  // namespace stentsim::workflows::report
