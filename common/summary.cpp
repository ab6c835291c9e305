#include "common/summary.hpp"

#include <sys/resource.h>

#include <chrono>
#include <yaml-cpp/yaml.h>

#include <fmt/format.h>

#include "common/error.hpp"
#include "common/files.hpp"

namespace stentsim {

void Summary::set(const std::string& name, double value, const std::string& unit) { qoi_[name] = {value, unit}; }
void Summary::set(const std::string& name, std::vector<double> value, const std::string& unit) {
  qoi_[name] = {std::move(value), unit};
}
void Summary::set_text(const std::string& name, const std::string& value) { qoi_[name] = {value, ""}; }
void Summary::set_run(double wall_time_s, double peak_memory_mb) {
  wall_time_s_ = wall_time_s;
  peak_memory_mb_ = peak_memory_mb;
  run_set_ = true;
}
void Summary::note(const std::string& key, const std::string& value) { notes_[key] = value; }

void Summary::write(const std::filesystem::path& file) const {
  YAML::Emitter out;
  out.SetDoublePrecision(12);
  out << YAML::BeginMap;
  out << YAML::Key << "qoi" << YAML::Value << YAML::BeginMap;
  for (const auto& [name, q] : qoi_) {
    out << YAML::Key << name << YAML::Value << YAML::BeginMap << YAML::Key << "value" << YAML::Value;
    if (auto d = std::get_if<double>(&q.value)) out << *d;
    else if (auto v = std::get_if<std::vector<double>>(&q.value)) out << YAML::Flow << *v;
    else out << std::get<std::string>(q.value);
    out << YAML::Key << "unit" << YAML::Value << q.unit << YAML::EndMap;
  }
  out << YAML::EndMap;
  out << YAML::Key << "wall_time_s" << YAML::Value << (run_set_ ? wall_time_s_ : process_wall_time_s());
  out << YAML::Key << "peak_memory_mb" << YAML::Value << (run_set_ ? peak_memory_mb_ : peak_memory_mb_self());
  if (!notes_.empty()) {
    out << YAML::Key << "notes" << YAML::Value << YAML::BeginMap;
    for (const auto& [k, v] : notes_) out << YAML::Key << k << YAML::Value << v;
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  files::write_atomic(file, std::string(out.c_str()) + "\n");
}

Summary Summary::read(const std::filesystem::path& file) {
  Summary s;
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
    for (const auto& kv : root["qoi"]) {
      const auto& v = kv.second["value"];
      std::string unit = kv.second["unit"] ? kv.second["unit"].as<std::string>() : "";
      if (v.IsSequence()) s.set(kv.first.as<std::string>(), v.as<std::vector<double>>(), unit);
      else {
        try {
          s.set(kv.first.as<std::string>(), v.as<double>(), unit);
        } catch (const YAML::Exception&) {
          s.set_text(kv.first.as<std::string>(), v.as<std::string>());
        }
      }
    }
    s.wall_time_s_ = root["wall_time_s"] ? root["wall_time_s"].as<double>() : 0.0;
    s.peak_memory_mb_ = root["peak_memory_mb"] ? root["peak_memory_mb"].as<double>() : 0.0;
    s.run_set_ = root["wall_time_s"] || root["peak_memory_mb"];
    if (root["notes"])
      for (const auto& kv : root["notes"]) s.notes_[kv.first.as<std::string>()] = kv.second.as<std::string>();
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}: not a valid summary.yaml: {}", file.string(), e.what()));
  }
  return s;
}

namespace {
const auto process_start = std::chrono::steady_clock::now();
}

double process_wall_time_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - process_start).count();
}

double peak_memory_mb_self() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace stentsim
