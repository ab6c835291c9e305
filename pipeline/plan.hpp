#pragma once
// The DAG of stages: who produces what, in which order stages run.
// Cycles, duplicate producers and inputs that nobody produces and that do not
// exist are errors at plan time.
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "pipeline/stage.hpp"

namespace stentsim::pipeline {

class Plan {
 public:
  Plan(std::vector<Stage> stages, std::filesystem::path work_dir);

  const std::vector<Stage>& stages() const { return stages_; }
  /// Stage indices in a valid execution order (ties keep declaration order).
  const std::vector<std::size_t>& order() const { return order_; }
  /// Direct upstream stages of stage i.
  const std::set<std::size_t>& upstream(std::size_t i) const { return upstream_[i]; }
  /// Stage i and everything it depends on, transitively.
  std::set<std::size_t> with_ancestors(std::size_t i) const;
  /// Index of a stage by name; throws InputError listing the names if unknown.
  std::size_t index(const std::string& name) const;
  /// All outputs of stage i, including its summary.
  std::vector<std::string> outputs(std::size_t i) const;
  const std::filesystem::path& work_dir() const { return work_dir_; }

 private:
  std::vector<Stage> stages_;
  std::filesystem::path work_dir_;
  std::vector<std::set<std::size_t>> upstream_;
  std::vector<std::size_t> order_;
};

}  // namespace stentsim::pipeline
