#pragma once
// The paper's numbers (workflows/report/paper_targets.yaml, a copy of
// validation/targets.yaml embedded at build time, so a report needs no file
// beside the binary): per example its setup pressure, run time and results.
#include <optional>
#include <string>
#include <vector>

namespace stentsim::workflows::report {

/// One entry under `results:`.
struct PaperResult {
  std::string name;                    ///< e.g. "diameter_at_max_pressure"
  std::optional<double> value;         ///< the paper's number, when it is one
  std::string text;                    ///< the paper's words, when it is a statement
  std::optional<double> tolerance;     ///< relative
  std::optional<double> tolerance_abs; ///< absolute, in the paper's unit
  bool report_only = false;
  bool inconsistent = false;
  std::string comment;  ///< the YAML comment on (and directly above) the entry
};

struct PaperCase {
  std::string key;  ///< e.g. "free_expansion_straight"
  std::vector<PaperResult> results;  ///< in file order
  /// The inflation pressure the numbers were taken at (MPa) and where it comes from.
  std::optional<double> pressure_max;
  std::string pressure_source;   ///< the targets key it is read from
  bool pressure_shared = false;  ///< taken from free_expansion_straight (the paper's one pressure)
  std::string pressure_comment;
  /// The paper's run time in seconds and on how many processes (0 = not given).
  std::optional<double> run_time_s;
  int run_processes = 0;
};

/// The embedded text of paper_targets.yaml (comments included).
const std::string& paper_targets_text();

/// The example `key` of the embedded targets; InputError listing the known
/// keys when there is no such example.
PaperCase paper_case(const std::string& key);

/// Same from any text in the targets format (`source` names it in errors).
/// An example without its own setup pressure takes free_expansion_straight's:
/// the paper inflates every example to "13 atm or 1.01 MPa" (Sections 3-4).
PaperCase parse_paper_case(const std::string& text, const std::string& key, const std::string& source);

/// The example keys in the text, in file order.
std::vector<std::string> paper_case_keys(const std::string& text, const std::string& source);

}  // namespace stentsim::workflows::report
