#pragma once
// The per-case manifest (manifest.yaml in the work folder): for each stage
// the hashes it ran with, its version, status, timings and memory.
#include <filesystem>
#include <map>
#include <optional>
#include <string>

namespace stentsim::pipeline {

struct StageRecord {
  std::string status;  // "ok" or "failed"
  std::string version;
  std::string config_hash;
  std::map<std::string, std::string> inputs;   // declared path -> content hash
  std::map<std::string, std::string> outputs;  // declared path -> content hash
  std::string finished;                        // ISO 8601 UTC
  double duration_s = 0;
  double peak_memory_mb = 0;
  std::string message;  // failure message
};

class Manifest {
 public:
  /// Reads `file`; a missing file is an empty manifest, a damaged one an InputError.
  static Manifest load(const std::filesystem::path& file);
  /// Writes atomically.
  void save(const std::filesystem::path& file) const;

  const StageRecord* find(const std::string& stage) const;
  void set(const std::string& stage, StageRecord record) { stages_[stage] = std::move(record); }
  std::string tool_version;
  const std::map<std::string, StageRecord>& stages() const { return stages_; }

 private:
  std::map<std::string, StageRecord> stages_;
};

std::string utc_now_iso8601();

}  // namespace stentsim::pipeline
