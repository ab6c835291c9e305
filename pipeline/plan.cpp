#include "pipeline/plan.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "common/error.hpp"

namespace fs = std::filesystem;

namespace stentsim::pipeline {

Plan::Plan(std::vector<Stage> stages, fs::path work_dir) : stages_(std::move(stages)), work_dir_(std::move(work_dir)) {
  const std::size_t n = stages_.size();
  std::map<std::string, std::size_t> producer;
  std::set<std::string> names;
  for (std::size_t i = 0; i < n; ++i) {
    if (!names.insert(stages_[i].name).second) throw InputError(fmt::format("pipeline: two stages are named '{}'", stages_[i].name));
    for (const auto& out : outputs(i)) {
      if (fs::path(out).is_absolute())
        throw InputError(fmt::format("pipeline: stage '{}' declares output '{}' outside the work folder", stages_[i].name, out));
      auto [it, fresh] = producer.emplace(out, i);
      if (!fresh)
        throw InputError(fmt::format("pipeline: '{}' is produced by both '{}' and '{}'", out, stages_[it->second].name, stages_[i].name));
    }
  }
  upstream_.assign(n, {});
  for (std::size_t i = 0; i < n; ++i) {
    for (const auto& in : stages_[i].inputs) {
      if (auto it = producer.find(in); it != producer.end()) {
        upstream_[i].insert(it->second);
      } else if (fs::path(in).is_absolute()) {
        if (!fs::exists(in))
          throw InputError(fmt::format("{}: input file of stage '{}' not found", in, stages_[i].name));
      } else {
        throw InputError(fmt::format("pipeline: stage '{}' needs '{}', which no stage produces", stages_[i].name, in));
      }
    }
  }
  // Kahn's algorithm; the smallest ready index first keeps declaration order.
  std::vector<std::size_t> indegree(n);
  for (std::size_t i = 0; i < n; ++i) indegree[i] = upstream_[i].size();
  std::set<std::size_t> ready;
  for (std::size_t i = 0; i < n; ++i)
    if (indegree[i] == 0) ready.insert(i);
  while (!ready.empty()) {
    std::size_t i = *ready.begin();
    ready.erase(ready.begin());
    order_.push_back(i);
    for (std::size_t j = 0; j < n; ++j)
      if (upstream_[j].count(i) && --indegree[j] == 0) ready.insert(j);
  }
  if (order_.size() != n) {
    std::vector<std::string> cyc;
    for (std::size_t i = 0; i < n; ++i)
      if (indegree[i] > 0) cyc.push_back(stages_[i].name);
    throw InputError(fmt::format("pipeline: the stages {} depend on each other in a cycle", fmt::join(cyc, ", ")));
  }
}

std::vector<std::string> Plan::outputs(std::size_t i) const {
  auto out = stages_[i].outputs;
  out.push_back(summary_output(stages_[i].name));
  return out;
}

std::set<std::size_t> Plan::with_ancestors(std::size_t i) const {
  std::set<std::size_t> seen{i};
  std::vector<std::size_t> todo{i};
  while (!todo.empty()) {
    std::size_t k = todo.back();
    todo.pop_back();
    for (std::size_t u : upstream_[k])
      if (seen.insert(u).second) todo.push_back(u);
  }
  return seen;
}

std::size_t Plan::index(const std::string& name) const {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < stages_.size(); ++i) {
    if (stages_[i].name == name) return i;
    names.push_back(stages_[i].name);
  }
  throw InputError(fmt::format("no stage named '{}' in this case; its stages are: {}", name, fmt::join(names, ", ")));
}

}  // namespace stentsim::pipeline
