#pragma once
// A cohort: one YAML file with a template case and a list of cases, each an
// id with overrides of any case key (issue 10). Validated like case files;
// errors name the cohort file, the case id and the key.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "workflows/case_config.hpp"

namespace stentsim::workflows {

struct CohortCase {
  std::string id;
  YAML::Node overrides;                    // merged into the template, key by key
  std::optional<std::string> expect_failure;  // stage at which this case is meant to fail
  std::string origin;                      // cases_from: "<key> from <file>" (for messages); empty for `cases`
  std::vector<std::string> stages;         // the stages of its pipeline plan, in order (set by load_cohort)
};

/// `backend: slurm` settings (`slurm:` map of the cohort file).
struct SlurmOptions {
  std::string partition;                  // empty: the cluster's default
  std::string time_limit;                 // sbatch --time (e.g. "30" or "1:00:00"); empty: the partition's
  std::string memory;                     // sbatch --mem (e.g. "4G"); empty: the partition's
  int cpus_per_case = 1;                  // --cpus-per-task
  std::vector<std::string> extra_options; // extra sbatch options ("extra_sbatch_options: --qos=short --mem-per-cpu=1G")
  double poll_interval_s = 1.0;           // squeue polling period
  double queue_patience_s = 300.0;        // how long squeue may fail before the follower gives up (the tasks keep running)
};

struct CohortConfig {
  std::filesystem::path file;
  std::string name;
  std::filesystem::path work_dir;          // <cohort>.work beside the file by default
  YAML::Node template_case;                // the template case (a map)
  std::filesystem::path template_dir;      // relative paths in the template resolve here
  std::vector<CohortCase> cases;           // `cases`, then one per file of each `cases_from` glob
  int workers = 0;                         // 0: the core count
  int ranks_per_case = 1;
  std::string backend = "local";           // local | slurm
  SlurmOptions slurm;
};

/// Reads and validates a cohort file, including every case's merged
/// configuration and its pipeline plan (so a missing input file is caught
/// here). Throws InputError naming the file, the case id and the key.
///
/// Cases come from `cases:` (id, overrides, expect_failure) and from
/// `cases_from:` (a map or a list of maps): `glob:` a file pattern relative to
/// the cohort file, `key:` the dotted case key each matched file is put in
/// (e.g. input.surface.lumen), optional `overrides:` and `expect_failure:` for
/// all of them. Their ids are the file names without extension; ids are unique
/// across both. In overrides a null value removes a template key.
CohortConfig load_cohort(const std::filesystem::path& file);

/// The case file of one case: template with overrides, work_dir "work".
YAML::Node merged_case(const CohortConfig& c, const CohortCase& k);

/// Writes each case's merged case file to <work_dir>/<id>/case.yaml (only if
/// its content changed, so runs stay incremental) and returns their paths.
std::vector<std::filesystem::path> materialize_cases(const CohortConfig& c);

/// A case's configuration as `stentsim run` in its folder sees it, without
/// writing anything in the work folder (for `cohort status`): its case.yaml
/// when that is up to date, else the merged case read from a temporary file
/// with the same work folder.
CaseConfig cohort_case_config(const CohortConfig& c, const CohortCase& k);

}  // namespace stentsim::workflows
