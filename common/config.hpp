#pragma once
// Validated reading of YAML configuration (case files, scenes, cohorts).
// Every error names the file, the line and column, the dotted key and what
// was expected; unknown keys are errors with a "did you mean" hint.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "common/units.hpp"

namespace stentsim {

/// Closed or open numeric bounds for a value.
struct Range {
  std::optional<double> min, max;
  bool min_inclusive = true, max_inclusive = true;
  static Range positive() { return {0.0, std::nullopt, false, true}; }
  static Range non_negative() { return {0.0, std::nullopt, true, true}; }
  static Range between(double lo, double hi) { return {lo, hi, true, true}; }
  static Range any() { return {}; }
  bool contains(double v) const;
  std::string describe() const;
};

/// A YAML map being read under a dotted path; tracks which keys were used so
/// that finish() can reject the ones nobody asked for.
class ConfigMap {
 public:
  /// Loads and parses `file`; throws InputError naming the file on a syntax error.
  static ConfigMap load(const std::filesystem::path& file);
  /// Parses YAML text that came from `file` (used for tests and overrides).
  static ConfigMap from_string(const std::string& text, const std::filesystem::path& file);
  ConfigMap(YAML::Node node, std::shared_ptr<const std::filesystem::path> file, std::string path);

  bool has(const std::string& key) const;

  // Scalars. A missing key without a default is an error.
  double number(const std::string& key, std::optional<double> def = std::nullopt, Range r = Range::any());
  int integer(const std::string& key, std::optional<int> def = std::nullopt, Range r = Range::any());
  bool boolean(const std::string& key, std::optional<bool> def = std::nullopt);
  std::string string(const std::string& key, std::optional<std::string> def = std::nullopt);
  /// A quantity with units ("13 atm"), converted to project units.
  double quantity(const std::string& key, const units::Dimension& dim, std::optional<double> def = std::nullopt,
                  Range r = Range::any());
  /// One of a fixed set of words.
  std::string choice(const std::string& key, const std::vector<std::string>& options,
                     std::optional<std::string> def = std::nullopt);
  /// A file path, resolved against the folder of the config file.
  std::filesystem::path path(const std::string& key, std::optional<std::filesystem::path> def = std::nullopt);
  std::vector<double> numbers(const std::string& key, std::size_t count,
                              std::optional<std::vector<double>> def = std::nullopt);

  /// A nested map (required unless `optional` and absent, then nullopt).
  ConfigMap map(const std::string& key);
  std::optional<ConfigMap> optional_map(const std::string& key);
  /// A list of maps.
  std::vector<ConfigMap> map_list(const std::string& key);

  /// Rejects keys that were never read. Call after reading everything.
  void finish() const;

  /// Throws InputError at this map's location (or at `key`'s if given).
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;

  const std::filesystem::path& file() const { return *file_; }
  const std::string& dotted_path() const { return path_; }
  const YAML::Node& node() const { return node_; }
  std::string key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

 private:
  YAML::Node scalar_node(const std::string& key);
  std::string where(const YAML::Node& n) const;

  YAML::Node node_;
  std::shared_ptr<const std::filesystem::path> file_;
  std::string path_;
  std::set<std::string> used_;
};

/// Deterministic text of a YAML node with map keys sorted: used to hash a
/// configuration slice so that key order does not make a stage stale.
std::string canonical_yaml(const YAML::Node& node);

/// Levenshtein distance, for "did you mean" hints.
std::size_t edit_distance(const std::string& a, const std::string& b);
/// The candidate nearest to `given` when it is near enough to be a likely
/// misspelling (distance <= max(2, |given| / 3)); empty otherwise.
std::string closest_name(const std::vector<std::string>& candidates, const std::string& given);

}  // namespace stentsim
