#pragma once
// Named arrays of doubles (and a few texts) that terms and the solver write
// into a checkpoint and read back on restart (issue 6). Keys are paths,
// "term/<index>:<name>/<field>"; a term with per-Gauss-point history stores
// one flat array per field, element-major, then quadrature point, then
// component (e.g. a plastic strain of 6 components at 3 points of 210
// elements: 3780 numbers), so a term can check the size against its own
// layout on load.
//
// File format (binary, native little-endian doubles): the magic line
// "stentsim checkpoint\n", uint32 format version (kFormatVersion), then
// uint64 #arrays × {uint32 key length, key, uint64 count, count doubles},
// uint64 #texts × {uint32 key length, key, uint64 length, bytes}.
#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace stentsim::solver {

class HistoryArchive {
 public:
  static constexpr std::uint32_t kFormatVersion = 2;  // 2: a trailing checksum (files::text_hash)

  void put(const std::string& key, std::span<const double> values) { arrays_[key].assign(values.begin(), values.end()); }
  void put(const std::string& key, double value) { arrays_[key] = {value}; }
  void put_text(const std::string& key, std::string text) { texts_[key] = std::move(text); }

  bool has(const std::string& key) const { return arrays_.count(key) != 0; }
  /// The array under `key`; throws InputError naming the checkpoint if it is
  /// missing or (expected_size >= 0) has another size.
  const std::vector<double>& get(const std::string& key, long long expected_size = -1) const;
  double get_scalar(const std::string& key) const { return get(key, 1)[0]; }
  const std::string& get_text(const std::string& key) const;
  bool has_text(const std::string& key) const { return texts_.count(key) != 0; }
  /// The text keys that start with `prefix`, sorted.
  std::vector<std::string> text_keys(const std::string& prefix) const {
    std::vector<std::string> keys;
    for (auto it = texts_.lower_bound(prefix); it != texts_.end() && it->first.compare(0, prefix.size(), prefix) == 0; ++it)
      keys.push_back(it->first);
    return keys;
  }

  /// Writes atomically (temporary name + rename).
  void write(const std::filesystem::path& file) const;
  /// Reads a checkpoint; InputError on a wrong magic, version or a truncated file.
  static HistoryArchive read(const std::filesystem::path& file);

 private:
  std::map<std::string, std::vector<double>> arrays_;
  std::map<std::string, std::string> texts_;
  std::string source_ = "checkpoint";
};

}  // namespace stentsim::solver
