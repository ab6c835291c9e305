#pragma once
// A stage of a make-like pipeline: a pure function from files to files.
// The engine knows nothing of the domain: stages declare their inputs,
// outputs, the configuration text they depend on and a version.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "common/summary.hpp"

namespace stentsim::pipeline {

class StageContext;

struct Stage {
  std::string name;
  /// Files the stage reads: relative paths are outputs of other stages (inside
  /// the work folder); absolute paths are external inputs and must exist.
  std::vector<std::string> inputs;
  /// Files (or folders, with a trailing '/') the stage writes, relative to the
  /// work folder. Every stage also writes "<name>/summary.yaml".
  std::vector<std::string> outputs;
  /// Canonical text of the configuration the stage depends on; a change makes it stale.
  std::string config;
  /// Bump when the stage's code changes what it writes.
  std::string version = "1";
  std::function<void(StageContext&)> run;
};

/// What a running stage sees: where to read, where to write (temporary names
/// that the engine renames into place on success), and its summary.
class StageContext {
 public:
  StageContext(const Stage& stage, std::filesystem::path work_dir, std::filesystem::path temp_dir);

  const Stage& stage() const { return stage_; }
  const std::filesystem::path& work_dir() const { return work_dir_; }
  /// Path to read a declared input from (exactly as declared).
  std::filesystem::path input(const std::string& declared) const;
  /// Temporary path to write a declared output to (its folder exists).
  std::filesystem::path output(const std::string& declared) const;
  /// The stage's summary.yaml content; the engine adds wall time and memory.
  Summary& summary() { return summary_; }

  /// A folder that outlives a failed or interrupted attempt of this stage (work/.resume/<stage>/,
  /// created here): what a long stage needs to continue where the last attempt stopped. The
  /// engine removes it once the stage has succeeded.
  std::filesystem::path resume_dir() const;
  /// Temporary location of an output (engine use).
  std::filesystem::path temp_path(const std::string& declared) const;

 private:
  const Stage& stage_;
  std::filesystem::path work_dir_, temp_dir_;
  Summary summary_;
};

/// The resume folder of stage `name` in `work_dir` (StageContext::resume_dir).
std::filesystem::path resume_dir(const std::filesystem::path& work_dir, const std::string& name);
/// Path of the summary every stage writes, relative to the work folder.
std::string summary_output(const std::string& stage_name);

}  // namespace stentsim::pipeline
