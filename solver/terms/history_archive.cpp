#include "solver/terms/history_archive.hpp"

#include <fmt/format.h>

#include <cstring>
#include <fstream>
#include <sstream>

#include "common/error.hpp"
#include "common/files.hpp"

namespace stentsim::solver {
namespace {

constexpr char kMagic[] = "stentsim checkpoint\n";

template <class T>
void put_raw(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}
void put_key(std::string& out, const std::string& key) {
  put_raw(out, static_cast<std::uint32_t>(key.size()));
  out += key;
}

struct Reader {
  const std::string& data;
  std::size_t at = 0;
  std::string file;
  void need(std::size_t n) const {
    // n from the file: compared without forming at + n (a damaged count must not wrap around).
    if (n > data.size() - at) throw InputError(fmt::format("{}: truncated checkpoint (at byte {})", file, at));
  }
  template <class T>
  T raw() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, data.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  std::string bytes(std::size_t n) {
    need(n);
    std::string s = data.substr(at, n);
    at += n;
    return s;
  }
};

}  // namespace

const std::vector<double>& HistoryArchive::get(const std::string& key, long long expected_size) const {
  auto it = arrays_.find(key);
  if (it == arrays_.end()) throw InputError(fmt::format("{}: no entry '{}' (a checkpoint of another scene?)", source_, key));
  if (expected_size >= 0 && static_cast<long long>(it->second.size()) != expected_size)
    throw InputError(fmt::format("{}: entry '{}' has {} values, expected {} (a checkpoint of another scene?)", source_, key,
                                 it->second.size(), expected_size));
  return it->second;
}

const std::string& HistoryArchive::get_text(const std::string& key) const {
  auto it = texts_.find(key);
  if (it == texts_.end()) throw InputError(fmt::format("{}: no text entry '{}'", source_, key));
  return it->second;
}

void HistoryArchive::write(const std::filesystem::path& file) const {
  std::string out(kMagic);
  put_raw(out, kFormatVersion);
  put_raw(out, static_cast<std::uint64_t>(arrays_.size()));
  for (const auto& [k, v] : arrays_) {
    put_key(out, k);
    put_raw(out, static_cast<std::uint64_t>(v.size()));
    out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
  }
  put_raw(out, static_cast<std::uint64_t>(texts_.size()));
  for (const auto& [k, t] : texts_) {
    put_key(out, k);
    put_raw(out, static_cast<std::uint64_t>(t.size()));
    out += t;
  }
  // A checksum of everything before it: a damaged file is an error, never a state.
  out += files::text_hash(out);
  files::write_atomic(file, out);
}

HistoryArchive HistoryArchive::read(const std::filesystem::path& file) {
  files::require_regular_file(file, "checkpoint");
  std::string data = files::read_text(file);
  Reader r{data, 0, file.string()};
  if (r.bytes(sizeof(kMagic) - 1) != kMagic) throw InputError(fmt::format("{}: not a stentsim checkpoint", file.string()));
  const auto version = r.raw<std::uint32_t>();
  if (version != kFormatVersion)
    throw InputError(fmt::format("{}: checkpoint format version {}, this build reads version {}", file.string(), version,
                                 kFormatVersion));
  const std::size_t sum_size = files::text_hash("").size();
  if (data.size() < r.at + sum_size) r.need(data.size() + 1);
  const std::string sum = data.substr(data.size() - sum_size);
  data.resize(data.size() - sum_size);
  if (files::text_hash(data) != sum)
    throw InputError(fmt::format("{}: the checkpoint is damaged (its checksum does not match its contents)", file.string()));
  HistoryArchive a;
  a.source_ = file.string();
  const auto na = r.raw<std::uint64_t>();
  for (std::uint64_t i = 0; i < na; ++i) {
    const std::string key = r.bytes(r.raw<std::uint32_t>());
    const auto n = r.raw<std::uint64_t>();
    if (n > (data.size() - r.at) / sizeof(double)) r.need(data.size() + 1);  // truncated (or a damaged count)
    std::vector<double> v(n);
    if (n > 0) std::memcpy(v.data(), data.data() + r.at, n * sizeof(double));  // an empty vector's data() may be null
    r.at += n * sizeof(double);
    a.arrays_[key] = std::move(v);
  }
  const auto nt = r.raw<std::uint64_t>();
  for (std::uint64_t i = 0; i < nt; ++i) {
    const std::string key = r.bytes(r.raw<std::uint32_t>());
    a.texts_[key] = r.bytes(r.raw<std::uint64_t>());
  }
  if (r.at != data.size()) throw InputError(fmt::format("{}: trailing bytes after the checkpoint", file.string()));
  return a;
}

}  // namespace stentsim::solver
