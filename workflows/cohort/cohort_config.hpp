#pragma once
// A cohort: one YAML file with a template case and a list of cases, each an
// id with overrides of any case key (issue 10). Validated like case files;
// errors name the cohort file, the case id and the key.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace stentsim::workflows {

struct CohortCase {
  std::string id;
  YAML::Node overrides;                    // merged into the template, key by key
  std::optional<std::string> expect_failure;  // stage at which this case is meant to fail
};

/// `backend: slurm` settings (`slurm:` map of the cohort file).
struct SlurmOptions {
  std::string partition;                  // empty: the cluster's default
  std::string time_limit;                 // sbatch --time (e.g. "30" or "1:00:00"); empty: the partition's
  std::string memory;                     // sbatch --mem (e.g. "4G"); empty: the partition's
  int cpus_per_case = 1;                  // --cpus-per-task
  std::vector<std::string> extra_options; // extra sbatch options ("extra_sbatch_options: --qos=short --mem-per-cpu=1G")
  double poll_interval_s = 1.0;           // squeue polling period
};

struct CohortConfig {
  std::filesystem::path file;
  std::string name;
  std::filesystem::path work_dir;          // <cohort>.work beside the file by default
  YAML::Node template_case;                // the template case (a map)
  std::filesystem::path template_dir;      // relative paths in the template resolve here
  std::vector<CohortCase> cases;
  int workers = 0;                         // 0: the core count
  int ranks_per_case = 1;
  std::string backend = "local";           // local | slurm
  SlurmOptions slurm;
};

/// Reads and validates a cohort file, including every case's merged
/// configuration. Throws InputError naming the file, the case id and the key.
CohortConfig load_cohort(const std::filesystem::path& file);

/// The case file of one case: template with overrides, work_dir "work".
YAML::Node merged_case(const CohortConfig& c, const CohortCase& k);

/// Writes each case's merged case file to <work_dir>/<id>/case.yaml (only if
/// its content changed, so runs stay incremental) and returns their paths.
std::vector<std::filesystem::path> materialize_cases(const CohortConfig& c);

}  // namespace stentsim::workflows
