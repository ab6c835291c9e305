#pragma once
// Runs a stability suite (stability_suite.hpp) one case at a time, each in a
// child process under its wall-clock limit, and classifies each case:
//   converged        exit 0 and no NaN/Inf in what it wrote
//   failed cleanly   non-zero exit, a message, and (a solver scene) the last
//                    converged state written: summary.yaml status "failed"
//                    with results.pvd; (a case file) the failing stage named
//                    in the manifest
//   failed uncleanly non-zero exit without the above (no message, no state,
//                    or exit 2: the suite's own input was rejected)
//   hang             still running at the limit (ended by us)
//   crash            ended by a signal (in a case file: a stage killed by one)
//   nan              NaN or Inf in any summary.yaml, CSV, VTU or VTP it wrote
// A case is "as expected" when its outcome is one it may end as and, for a
// clean failure, the message holds the expected text, and a comparison
// (compare:) holds. Results: stability.csv and stability.md.
#include <filesystem>
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/summary.hpp"
#include "workflows/study/stability/child_run.hpp"
#include "workflows/study/stability/stability_suite.hpp"

namespace stentsim::study {

struct StabilityOutcome {
  std::string id;
  std::string outcome;            ///< converged | failed cleanly | failed uncleanly | hang | crash | nan
  bool as_expected = false;
  std::string check;              ///< why not as expected ("" when it is)
  ChildRun run;
  double limit_s = 0;
  std::optional<double> steps, iterations, cuts, final_time;  ///< from the solver's summary.yaml
  std::string message;            ///< the failure's message (or the NaN's place)
  std::map<std::string, std::vector<double>> qois;  ///< numeric QoIs of its summary.yaml
};

struct StabilityOptions {
  std::filesystem::path out_dir;  ///< each case runs in out_dir/<id>/
  std::string subset = "all";     ///< "quick" or "all"
  std::string binary;             ///< the stentsim executable
  std::vector<std::string> only;  ///< case ids to run (empty: the subset)
};

struct StabilityReport {
  std::string suite;
  std::vector<StabilityOutcome> cases;
  int unexpected() const;
};

/// The outcome of one finished case from its run and the files in `case_dir`.
StabilityOutcome classify_case(const StabilityCase& c, const ChildRun& run, const std::filesystem::path& case_dir,
                               const std::filesystem::path& log);

/// First NaN or Inf in the files under `dir` (summary.yaml, *.csv, *.vtu,
/// *.vtp): "file: array" or "" when there is none.
std::string find_non_finite(const std::filesystem::path& dir);

/// Runs the cases of the subset in order, writing progress lines to `out`
/// and stability.csv + stability.md into out_dir after every case.
StabilityReport run_stability_suite(const StabilitySuite& s, const StabilityOptions& o, std::ostream& out);

/// The suite's summary.yaml (DESIGN.md §6): counts per outcome class, as
/// expected or not, the cases' summed wall time and largest peak memory.
Summary stability_summary(const StabilityReport& r);
/// Writes stability.csv, stability.md and summary.yaml into `dir` (atomically).
void write_stability_tables(const StabilityReport& r, const std::filesystem::path& dir);

}  // namespace stentsim::study
