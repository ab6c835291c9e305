#include "pipeline/manifest.hpp"

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <chrono>

#include "common/error.hpp"
#include "common/files.hpp"

namespace stentsim::pipeline {

std::string utc_now_iso8601() {
  return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::chrono::system_clock::to_time_t(std::chrono::system_clock::now())));
}

const char* to_string(ErrorKind k) {
  switch (k) {
    case ErrorKind::none: return "none";
    case ErrorKind::input: return "input";
    case ErrorKind::compute: return "compute";
    case ErrorKind::crash: return "crash";
    case ErrorKind::interrupted: return "interrupted";
    case ErrorKind::unknown: break;
  }
  return "unknown";
}

ErrorKind error_kind_from(std::string_view name) {
  for (ErrorKind k : {ErrorKind::none, ErrorKind::input, ErrorKind::compute, ErrorKind::crash, ErrorKind::interrupted})
    if (name == to_string(k)) return k;
  return ErrorKind::unknown;
}

Manifest Manifest::load(const std::filesystem::path& file) {
  Manifest m;
  if (!std::filesystem::exists(file)) return m;
  try {
    YAML::Node root = YAML::LoadFile(file.string());
    if (root["tool_version"]) m.tool_version = root["tool_version"].as<std::string>();
    for (const auto& kv : root["stages"]) {
      const YAML::Node& n = kv.second;
      StageRecord r;
      r.status = n["status"].as<std::string>();
      r.version = n["version"].as<std::string>("");
      r.config_hash = n["config_hash"].as<std::string>("");
      if (n["inputs"]) r.inputs = n["inputs"].as<std::map<std::string, std::string>>();
      if (n["outputs"]) r.outputs = n["outputs"].as<std::map<std::string, std::string>>();
      r.finished = n["finished"].as<std::string>("");
      r.duration_s = n["duration_s"].as<double>(0.0);
      r.peak_memory_mb = n["peak_memory_mb"].as<double>(0.0);
      r.message = n["message"].as<std::string>("");
      r.error_kind = r.status == "ok" ? ErrorKind::none : error_kind_from(n["error_kind"].as<std::string>(""));
      m.stages_[kv.first.as<std::string>()] = std::move(r);
    }
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}: damaged manifest ({}); delete it to rebuild the case from scratch", file.string(), e.what()));
  }
  return m;
}

void Manifest::save(const std::filesystem::path& file) const {
  YAML::Emitter out;
  out << YAML::Comment("stentsim stage manifest: written by the runner, do not edit");
  out << YAML::BeginMap << YAML::Key << "tool_version" << YAML::Value << tool_version;
  out << YAML::Key << "stages" << YAML::Value << YAML::BeginMap;
  for (const auto& [name, r] : stages_) {
    out << YAML::Key << name << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "status" << YAML::Value << r.status;
    out << YAML::Key << "version" << YAML::Value << r.version;
    out << YAML::Key << "config_hash" << YAML::Value << r.config_hash;
    out << YAML::Key << "inputs" << YAML::Value << r.inputs;
    out << YAML::Key << "outputs" << YAML::Value << r.outputs;
    out << YAML::Key << "finished" << YAML::Value << r.finished;
    out << YAML::Key << "duration_s" << YAML::Value << r.duration_s;
    out << YAML::Key << "peak_memory_mb" << YAML::Value << r.peak_memory_mb;
    if (!r.message.empty()) out << YAML::Key << "message" << YAML::Value << r.message;
    if (r.status != "ok") out << YAML::Key << "error_kind" << YAML::Value << to_string(r.error_kind);
    out << YAML::EndMap;
  }
  out << YAML::EndMap << YAML::EndMap;
  files::write_atomic(file, std::string(out.c_str()) + "\n");
}

const StageRecord* Manifest::find(const std::string& stage) const {
  auto it = stages_.find(stage);
  return it == stages_.end() ? nullptr : &it->second;
}

}  // namespace stentsim::pipeline
