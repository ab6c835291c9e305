#pragma once
// The stability suite file of `stentsim study stability` (issue 11): cases
// that must converge or fail cleanly, each a solver scene (`stentsim solve`),
// a case file (`stentsim run --until STAGE`) or any command, with dotted-key
// overrides of the scene or case, the subset it belongs to, its recorded
// time (the wall-clock limit is limit_factor x that, at least min_limit_s)
// and what it is expected to end as. Every key is validated; errors name the
// suite file, the line and the key. examples/studies/stability/stability.yaml
// shows every part.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace stentsim::study {

struct StabilityCase {
  enum class Kind { scene, case_file, exec } kind = Kind::scene;
  std::string id;
  std::string subset = "all";                  ///< "quick": also in the quick subset
  std::filesystem::path input;                 ///< scene or case file (resolved)
  /// dotted key -> value; "{suite_dir}" in a text value is the suite file's folder
  /// (the input copy runs in the case's own folder, so files beside the suite need it)
  std::vector<std::pair<std::string, YAML::Node>> set;
  std::vector<std::string> args;               ///< extra arguments (solve: e.g. --linear-solver gmres_ilu)
  std::string until;                           ///< case_file: `run --until`
  std::vector<std::string> exec;               ///< exec: the command
  double time_s = 6;                           ///< recorded time
  /// Outcomes this case may end as: "converged", "failed cleanly" (one or both).
  std::vector<std::string> expect{"converged"};
  std::string message;                         ///< a clean failure's message must contain this
  std::string failed_stage;                    ///< case_file: the stage expected to fail
  struct Compare {
    std::string case_id, qoi;
    double tolerance = 0;
  };
  std::optional<Compare> compare;              ///< |qoi - case's qoi|_inf <= tolerance
};

struct StabilitySuite {
  std::filesystem::path file;
  std::string name;
  double limit_factor = 10, min_limit_s = 60;
  std::vector<StabilityCase> cases;
  /// The wall-clock limit of a case: max(min_limit_s, limit_factor * time_s).
  double limit_s(const StabilityCase& c) const;
};

/// Reads and validates a suite file (InputError naming file, line and key).
StabilitySuite load_stability_suite(const std::filesystem::path& file);

/// Sets `dotted` ("bodies.0.materials.0.neo_hooke.nu") in `root`; sequence
/// items by index. Every key before the last must exist. Throws
/// std::invalid_argument naming the part of the path that is missing.
void set_dotted_key(YAML::Node root, const std::string& dotted, const YAML::Node& value);

}  // namespace stentsim::study
