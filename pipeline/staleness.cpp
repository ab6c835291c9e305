#include "pipeline/staleness.hpp"

#include <fmt/format.h>

#include <filesystem>

#include "common/files.hpp"

namespace fs = std::filesystem;

namespace stentsim::pipeline {
namespace {
fs::path resolve(const Plan& plan, const std::string& declared) {
  fs::path p(declared);
  return p.is_absolute() ? p : plan.work_dir() / p;
}
std::string hash_or_missing(const fs::path& p) { return fs::exists(p) ? files::content_hash(p) : "missing"; }
}  // namespace

std::map<std::string, std::string> hash_inputs(const Plan& plan, std::size_t i) {
  std::map<std::string, std::string> h;
  for (const auto& in : plan.stages()[i].inputs) h[in] = hash_or_missing(resolve(plan, in));
  return h;
}

std::map<std::string, std::string> hash_outputs(const Plan& plan, std::size_t i) {
  std::map<std::string, std::string> h;
  for (const auto& out : plan.outputs(i)) h[out] = hash_or_missing(resolve(plan, out));
  return h;
}

std::vector<std::string> stale_reasons(const Plan& plan, std::size_t i, const Manifest& manifest) {
  const Stage& s = plan.stages()[i];
  const StageRecord* r = manifest.find(s.name);
  if (!r) return {"never run"};
  if (r->status != "ok") return {"last run failed" + (r->message.empty() ? std::string() : ": " + r->message)};
  std::vector<std::string> why;
  if (r->version != s.version) why.push_back(fmt::format("stage version changed ({} -> {})", r->version, s.version));
  if (r->config_hash != files::text_hash(s.config)) why.push_back("configuration changed");
  for (const auto& [path, hash] : hash_inputs(plan, i)) {
    auto it = r->inputs.find(path);
    if (hash == "missing") why.push_back(fmt::format("input {} is missing", path));
    else if (it == r->inputs.end() || it->second != hash) why.push_back(fmt::format("input {} changed", path));
  }
  for (const auto& [path, hash] : hash_outputs(plan, i)) {
    auto it = r->outputs.find(path);
    if (hash == "missing") why.push_back(fmt::format("output {} is missing", path));
    else if (it == r->outputs.end() || it->second != hash) why.push_back(fmt::format("output {} was modified", path));
  }
  return why;
}

}  // namespace stentsim::pipeline
