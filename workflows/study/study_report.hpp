#pragma once
// What an error study reports: each run's error against the reference, the
// order along each refinement line (fitted, pairwise, Richardson + GCI), the
// Pareto front of error against wall time and the cheapest run within the
// tolerance; written as study.csv, study.md and PNG/SVG plots.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "workflows/plots/figure.hpp"
#include "workflows/study/convergence.hpp"
#include "workflows/study/run_executor.hpp"
#include "workflows/study/study_config.hpp"
#include "workflows/study/study_runs.hpp"

namespace stentsim::study {

struct LineSummary {
  std::string label, knob;
  std::vector<std::size_t> runs;   ///< runs with a value, in the knob's order
  std::vector<double> h, error, value;
  std::optional<double> theoretical_order;  ///< the knob's for this line (theoretical_order_for)
  std::optional<double> fitted_order;
  std::vector<double> pairwise_orders;
  std::optional<Richardson> richardson;  ///< from the QoI values alone (three finest)
};

struct StudyOutcome {
  std::vector<double> value;       ///< scalar QoI per run (norm for vectors); NaN when missing
  std::vector<std::vector<double>> reference;  ///< per run (empty when none)
  std::vector<double> error;       ///< NaN when unknown
  std::vector<LineSummary> lines;
  std::vector<std::size_t> pareto; ///< runs on the front, by increasing wall time
  std::optional<std::size_t> cheapest;  ///< cheapest run with error <= tolerance
  std::string reference_note;      ///< how the reference was obtained
  /// The error kind used: the study's, except that a relative error becomes
  /// absolute (/ error_scale) when the QoI tends to 0 (error_note says why).
  bool relative_error = true;
  std::string error_note;          ///< non-empty when the error kind was changed
};

/// A run that succeeded but whose summary.yaml does not hold the study's QoI
/// (a typo in `qoi:`, or a command that does not compute it) becomes a failed
/// row whose message names the QoI, the run and the QoIs that are there
/// (closest name first, "did you mean"). Returns how many runs were marked.
/// Without this the run would silently drop out of the errors and the study
/// would exit 0 with an empty report.
int fail_runs_missing_qoi(const StudyConfig& study, const StudyPlan& plan, std::vector<RunResult>& results);

/// Errors, orders, front. Throws InputError for a study whose reference does
/// not fit its QoI (component count). A relative error against a reference
/// that vanishes (kVanishingQoi) is reported as absolute, with error_note.
StudyOutcome evaluate_study(const StudyConfig& study, const StudyPlan& plan, const std::vector<RunResult>& results);

/// The error-against-h figure: per line with mesh sizes, its errors as
/// markers and, when an order was fitted, the fitted power law as a dashed
/// line of the same colour labelled "<line> fit p = <order>".
plots::Figure error_vs_h_figure(const StudyConfig& study, const StudyOutcome& outcome);

/// Files written into `out_dir`.
struct ReportFiles {
  std::filesystem::path csv, markdown;
  std::vector<std::filesystem::path> plots;
};

ReportFiles write_report(const StudyConfig& study, const StudyPlan& plan, const std::vector<RunResult>& results,
                         const StudyOutcome& outcome, const std::filesystem::path& out_dir);

}  // namespace stentsim::study
