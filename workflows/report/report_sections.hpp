#pragma once
// The report's sections, each from inputs already read and checked
// (report.cpp reads them all before anything is written).
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/summary.hpp"
#include "pipeline/manifest.hpp"
#include "workflows/report/paper_targets.hpp"
#include "workflows/report/report.hpp"
#include "workflows/report/report_figures.hpp"
#include "workflows/report/report_inputs.hpp"
#include "workflows/report/report_writer.hpp"
#include "workflows/report/target_table.hpp"

namespace stentsim::workflows::report {

/// An earlier stage's summary.yaml, when it has one.
struct StageSummary {
  std::string stage;
  std::filesystem::path file;
  Summary summary;
};

/// Everything the sections draw from.
struct ReportContext {
  const ReportInput* in = nullptr;
  pipeline::Manifest manifest;
  std::vector<std::string> stages;  ///< the manifest's stages in pipeline order, without `report`
  std::vector<StageSummary> stage_summaries;
  Summary solve;
  std::vector<std::pair<std::string, std::string>> solve_notes;
  History history;
  std::optional<std::vector<PvdFrame>> pvd;  ///< nullopt: results.pvd is not there
  std::optional<PaperCase> paper;
  std::filesystem::path report_dir;  ///< links in the report are relative to it
};

/// `path` relative to the work folder when it lies inside, else as given.
std::string shown_path(const ReportContext& c, const std::filesystem::path& path);

/// "12.3 s", "4.2 min", "1.53 h".
std::string duration_text(double seconds);

void add_case_section(Document& doc, const ReportContext& c, const std::string& written_at);
void add_run_section(Document& doc, const ReportContext& c);
void add_results_section(Document& doc, const ReportContext& c);
/// Adds the comparison; returns the judged table (nullopt without paper numbers).
std::optional<TargetTable> add_targets_section(Document& doc, const ReportContext& c);
void add_figures_section(Document& doc, const ReportContext& c, const FigureSet& figures);
void add_pictures_section(Document& doc, const ReportContext& c);

}  // namespace stentsim::workflows::report
