#pragma once
// The report's figures from solve/history.csv and solve/summary.yaml, each
// written as PNG (inlined in the HTML) and SVG (for papers and slides).
// A figure whose data is absent is not drawn; the report lists it with the reason.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "common/summary.hpp"
#include "workflows/report/report_inputs.hpp"

namespace stentsim::workflows::report {

/// A point of the paper's to mark on a figure (e.g. the diameter at max pressure).
struct PaperPoint {
  std::string label;
  double x = 0, y = 0;
};

struct FigureInputs {
  const History* history = nullptr;
  const Summary* solve = nullptr;
  std::vector<PaperPoint> diameter_vs_pressure;  ///< drawn on the diameter-pressure figure
};

struct WrittenFigure {
  std::string name;     ///< file stem, e.g. "stent_diameter_vs_pressure"
  std::string title;
  std::string caption;  ///< what is drawn and from which columns
  std::filesystem::path png, svg;
};

struct OmittedFigure {
  std::string title;
  std::string why;
};

struct FigureSet {
  std::vector<WrittenFigure> written;
  std::vector<OmittedFigure> omitted;
};

/// Draws every figure whose data is present into `figure_dir` (created).
FigureSet write_figures(const FigureInputs& in, const std::filesystem::path& figure_dir);

}  // namespace stentsim::workflows::report
