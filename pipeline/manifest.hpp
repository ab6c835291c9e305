#pragma once
// The per-case manifest (manifest.yaml in the work folder): for each stage
// the hashes it ran with, its version, status, timings and memory.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace stentsim::pipeline {

/// Why a stage failed: a bad input (the stage exited 2 on an InputError: the
/// user fixes a file or a setting), a computation that did not complete (exit 1),
/// a crash (a signal other than an interrupt), an interrupt. `unknown` is a
/// failed record that does not say (written before kinds were recorded).
enum class ErrorKind { none, input, compute, crash, interrupted, unknown };
const char* to_string(ErrorKind k);
/// The kind a manifest names; anything else is `unknown`.
ErrorKind error_kind_from(std::string_view name);

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
  ErrorKind error_kind = ErrorKind::none;  // a failed record's kind
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
