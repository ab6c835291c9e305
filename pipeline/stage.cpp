#include "pipeline/stage.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "common/error.hpp"

namespace fs = std::filesystem;

namespace stentsim::pipeline {

std::string summary_output(const std::string& stage_name) { return stage_name + "/summary.yaml"; }

StageContext::StageContext(const Stage& stage, fs::path work_dir, fs::path temp_dir)
    : stage_(stage), work_dir_(std::move(work_dir)), temp_dir_(std::move(temp_dir)) {}

fs::path StageContext::input(const std::string& declared) const {
  if (std::find(stage_.inputs.begin(), stage_.inputs.end(), declared) == stage_.inputs.end())
    throw ComputeError(fmt::format("stage '{}' reads '{}', which it did not declare as an input", stage_.name, declared));
  fs::path p(declared);
  return p.is_absolute() ? p : work_dir_ / p;
}

fs::path resume_dir(const fs::path& work_dir, const std::string& name) { return work_dir / ".resume" / name; }

fs::path StageContext::resume_dir() const {
  const fs::path d = pipeline::resume_dir(work_dir_, stage_.name);
  fs::create_directories(d);
  return d;
}

fs::path StageContext::temp_path(const std::string& declared) const { return temp_dir_ / fs::path(declared); }

fs::path StageContext::output(const std::string& declared) const {
  if (declared != summary_output(stage_.name) &&
      std::find(stage_.outputs.begin(), stage_.outputs.end(), declared) == stage_.outputs.end())
    throw ComputeError(fmt::format("stage '{}' writes '{}', which it did not declare as an output", stage_.name, declared));
  fs::path p = temp_path(declared);
  fs::create_directories(declared.ends_with('/') ? p : p.parent_path());
  return p;
}

}  // namespace stentsim::pipeline
