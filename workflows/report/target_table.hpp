#pragma once
// The comparison with the paper: which of our summary QoIs answers which
// entry of paper_targets.yaml (one table, target_table.cpp), and the verdict
// per entry under the targets file's rules (tolerance relative, tolerance_abs
// absolute; report_only and inconsistent entries are shown, not judged; a
// value the run did not compute is not judged; at another inflation pressure
// than the paper's, nothing that depends on it is judged).
#include <optional>
#include <string>
#include <vector>

#include "common/summary.hpp"
#include "workflows/report/paper_targets.hpp"

namespace stentsim::workflows::report {

/// Which summary QoI(s) answer a targets entry.
struct TargetMapping {
  std::string example;                    ///< targets key, e.g. "generic_artery_case1"
  std::string target;                     ///< entry under results:
  std::vector<std::string> summary_keys;  ///< one to compare; several are listed for a statement
  std::string paper_unit;                 ///< the unit of the paper's number ("" = dimensionless)
  bool report_only = false;               ///< not judged even when the targets file gives a tolerance
  bool depends_on_pressure = true;        ///< false: taken before the inflation (prestress)
  std::string why;                        ///< why it is not judged, or what is compared
};

/// The one table of mappings, for every example of paper_targets.yaml.
const std::vector<TargetMapping>& target_mappings();

/// The mapping of one entry, or nullptr.
const TargetMapping* find_mapping(const std::string& example, const std::string& target);

enum class Verdict { pass, fail, report_only, inconsistent, not_computed, different_pressure };

/// "pass", "FAIL", "report only", "inconsistent in paper", "not computed", "different pressure".
std::string verdict_text(Verdict v);

struct TargetRow {
  std::string quantity;    ///< "diameter_at_max_pressure (stent_diameter_max)"
  std::string paper;       ///< "2.59 mm"
  std::string tolerance;   ///< "±3 % (relative)", "±2 % (absolute)", "" when none
  std::string ours;        ///< "2.601 mm", or "" when not computed
  std::string difference;  ///< "+0.011 mm (+0.4 %)", or ""
  Verdict verdict = Verdict::not_computed;
  std::string why;         ///< why it is judged so (footnote), may be ""
};

/// Whether the case runs at the paper's pressure.
struct PressureCheck {
  bool known = false;    ///< the paper's pressure is known
  bool matches = false;  ///< within 0.5 % (the paper's 1.01 MPa has three digits)
  std::string statement; ///< one sentence for the report
};

PressureCheck check_pressure(const PaperCase& paper, double case_pressure_max);

struct TargetTable {
  std::vector<TargetRow> rows;
  PressureCheck pressure;
  int passed = 0, failed = 0, judged = 0;  ///< judged = passed + failed
  int not_computed = 0, not_judged = 0;    ///< not_judged: report only, inconsistent, different pressure
};

/// Judges every results entry of `paper` against `ours` at the case's pressure.
TargetTable judge_targets(const PaperCase& paper, const Summary& ours, double case_pressure_max);

/// `value` (in `from`) expressed in `to`; nullopt when the units cannot be
/// compared. Equal spellings ("N mm", "N*mm", "Nmm") need no conversion; an
/// empty `from` is taken to be `to`.
std::optional<double> convert_unit(double value, const std::string& from, const std::string& to);

}  // namespace stentsim::workflows::report
