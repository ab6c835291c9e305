#include "solver/app/checkpoint.hpp"

#include <fmt/format.h>

#include <span>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "solver/io/scene.hpp"

namespace stentsim::solver {

void SolverCheckpoint::put(HistoryArchive& out) const {
  out.put("solver/u", std::span<const double>(u.data(), static_cast<std::size_t>(u.size())));
  out.put("solver/time", time);
  out.put("solver/next_dt", next_dt);
  out.put("solver/newton_iterations", static_cast<double>(counters.newton_iterations));
  out.put("solver/linear_iterations", static_cast<double>(counters.linear_iterations));
  out.put("solver/step_cuts", static_cast<double>(counters.step_cuts));
  out.put("solver/steps", static_cast<double>(counters.steps));
  out.put("solver/predicted_steps", static_cast<double>(counters.predicted_steps));
  out.put("solver/floor_steps", static_cast<double>(counters.floor_steps));
  out.put("solver/worst_floor", counters.worst_floor);
  out.put("solver/last_increment", std::span<const double>(last_increment.data(), static_cast<std::size_t>(last_increment.size())));
  out.put("solver/last_dt", last_dt);
}

SolverCheckpoint SolverCheckpoint::get(const HistoryArchive& in, long long dofs) {
  SolverCheckpoint c;
  const auto& u = in.get("solver/u", dofs);
  c.u = Eigen::Map<const Eigen::VectorXd>(u.data(), static_cast<Eigen::Index>(u.size()));
  c.time = in.get_scalar("solver/time");
  c.next_dt = in.get_scalar("solver/next_dt");
  c.counters.newton_iterations = static_cast<long>(in.get_scalar("solver/newton_iterations"));
  c.counters.linear_iterations = static_cast<long>(in.get_scalar("solver/linear_iterations"));
  c.counters.step_cuts = static_cast<long>(in.get_scalar("solver/step_cuts"));
  c.counters.steps = static_cast<int>(in.get_scalar("solver/steps"));
  // Checkpoints written without a predictor state resume without a guess for their first step.
  if (in.has("solver/predicted_steps")) c.counters.predicted_steps = static_cast<int>(in.get_scalar("solver/predicted_steps"));
  if (in.has("solver/floor_steps")) c.counters.floor_steps = static_cast<int>(in.get_scalar("solver/floor_steps"));
  if (in.has("solver/worst_floor")) c.counters.worst_floor = in.get_scalar("solver/worst_floor");
  if (in.has("solver/last_increment") && !in.get("solver/last_increment").empty()) {
    const auto& inc = in.get("solver/last_increment", dofs);
    c.last_increment = Eigen::Map<const Eigen::VectorXd>(inc.data(), static_cast<Eigen::Index>(inc.size()));
  }
  if (in.has("solver/last_dt")) c.last_dt = in.get_scalar("solver/last_dt");
  return c;
}

std::map<std::string, std::string> scene_state_hashes(const SceneDesc& scene) {
  std::map<std::string, std::string> parts;
  for (const auto& [section, text] : scene.state_sections) parts["section " + section] = files::text_hash(text);
  const std::filesystem::path dir = std::filesystem::absolute(scene.file).lexically_normal().parent_path();
  for (const auto& f : scene.state_files)
    parts["file " + f.lexically_relative(dir).string()] = std::filesystem::exists(f) ? files::content_hash(f) : "missing";
  return parts;
}

std::map<std::string, std::string> state_fingerprint(const SceneDesc& scene, const std::map<std::string, std::string>& scene_parts,
                                                     double t) {
  std::map<std::string, std::string> parts = scene_parts;
  for (const auto& [name, curve] : scene.curves) {
    // The points up to t and the value at t: what the loads were until the checkpoint.
    std::string text;
    for (const auto& [ti, vi] : curve.points())
      if (ti <= t) text += fmt::format("{:.17g} {:.17g}\n", ti, vi);
    text += fmt::format("at {:.17g}: {:.17g}\n", t, curve(t));
    parts["load curve " + name] = files::text_hash(text);
  }
  return parts;
}

void put_fingerprint(HistoryArchive& out, const std::map<std::string, std::string>& parts) {
  for (const auto& [part, hash] : parts) out.put_text("solver/state/" + part, hash);
}

namespace {
// The parts that differ between a checkpoint's fingerprint and `parts`, or empty.
std::string fingerprint_difference(const HistoryArchive& in, const std::map<std::string, std::string>& parts) {
  std::string differ;
  for (const auto& [part, hash] : parts) {
    const std::string key = "solver/state/" + part;
    if (in.has_text(key) && in.get_text(key) == hash) continue;
    differ += fmt::format("{}{}{}", differ.empty() ? "" : ", ", part, in.has_text(key) ? "" : " (not in the checkpoint)");
  }
  for (const std::string& key : in.text_keys("solver/state/"))
    if (!parts.count(key.substr(13))) differ += fmt::format("{}{} (not in the scene)", differ.empty() ? "" : ", ", key.substr(13));
  return differ;
}
}  // namespace

void check_fingerprint(const HistoryArchive& in, const std::map<std::string, std::string>& parts,
                       const std::string& checkpoint, const std::string& scene) {
  const std::string differ = fingerprint_difference(in, parts);
  if (!differ.empty())
    throw InputError(fmt::format("{}: the checkpoint was written by another scene than {} (what differs: {}); a checkpoint "
                                 "resumes only the run that wrote it: run without --restart", checkpoint, scene, differ));
}

std::string checkpoint_refusal(const SceneDesc& scene, const std::filesystem::path& file) {
  if (!std::filesystem::is_regular_file(file)) return "there is no checkpoint";
  try {
    const HistoryArchive ck = HistoryArchive::read(file);
    const std::string differ =
        fingerprint_difference(ck, state_fingerprint(scene, scene_state_hashes(scene), ck.get_scalar("solver/time")));
    return differ.empty() ? std::string() : fmt::format("it was written by another scene (what differs: {})", differ);
  } catch (const InputError& e) {  // damaged, truncated, another format: not an I/O failure, which propagates
    return fmt::format("it cannot be read ({})", e.what());
  }
}

}  // namespace stentsim::solver
