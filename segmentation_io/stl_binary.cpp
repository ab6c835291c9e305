#include "segmentation_io/stl_binary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <vector>

#include "common/error.hpp"
#include "common/log.hpp"

namespace stentsim::segmentation {
namespace {

constexpr std::uintmax_t kHeader = 84, kRecord = 50;

// ASCII STL: "solid" after optional white space, and the first kilobyte text (bytes of
// 0x80 and above allowed: a UTF-8 or Latin-1 solid name) with no control characters.
bool looks_ascii(const std::vector<char>& head) {
  std::size_t i = 0;
  while (i < head.size() && std::isspace(static_cast<unsigned char>(head[i]))) ++i;
  if (head.size() - i < 5 || std::strncmp(head.data() + i, "solid", 5) != 0) return false;
  return std::all_of(head.begin(), head.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u == '\n' || u == '\r' || u == '\t' || (u >= 32 && u != 127);
  });
}

float read_float(const char* p) {
  float f;
  std::memcpy(&f, p, sizeof f);  // STL is little-endian, as every platform stentsim builds on
  return f;
}

}  // namespace

std::optional<TriSurface> read_binary_stl(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(fmt::format("{}: cannot read the file's size: {}", name, ec.message()));
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open the file", name));
  std::vector<char> head(static_cast<std::size_t>(std::min<std::uintmax_t>(size, 1024)));
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  std::uint32_t count = 0;
  if (size >= kHeader) std::memcpy(&count, head.data() + 80, sizeof count);
  const std::uintmax_t expected = kHeader + kRecord * static_cast<std::uintmax_t>(count);
  if (size != expected && looks_ascii(head)) return std::nullopt;
  if (size < kHeader)
    throw InputError(fmt::format("{}: {} bytes is neither an ASCII STL (it does not start with 'solid' followed by text) "
                                 "nor a binary one (84 bytes of header and count at least)", name, size));
  if (size < expected)
    throw InputError(fmt::format("{}: binary STL cut short: its header counts {} triangles, which take {} bytes, but the "
                                 "file has {} (a copy or download that did not finish?)", name, count, expected, size));
  if (size > expected)
    log::warn("{}: binary STL with {} bytes after the {} triangles its header counts; those bytes are ignored", name,
              size - expected, count);
  if (count == 0) throw InputError(fmt::format("{}: the binary STL holds no triangles", name));
  in.seekg(static_cast<std::streamoff>(kHeader));
  std::vector<char> records(static_cast<std::size_t>(kRecord * count));
  in.read(records.data(), static_cast<std::streamsize>(records.size()));
  if (!in) throw InputError(fmt::format("{}: reading the {} triangles failed", name, count));
  TriSurface s;
  s.triangles.reserve(count);
  std::map<std::array<float, 3>, int> index;  // exact repeats of a vertex
  for (std::uint32_t t = 0; t < count; ++t) {
    const char* r = records.data() + kRecord * t + 12;  // past the facet normal
    std::array<int, 3> tri{};
    for (int v = 0; v < 3; ++v) {
      const std::array<float, 3> x{read_float(r + 12 * v), read_float(r + 12 * v + 4), read_float(r + 12 * v + 8)};
      // Before the map: a NaN compares equal to every key and would merge into another vertex.
      if (!std::all_of(x.begin(), x.end(), [](float c) { return std::isfinite(c); }))
        throw InputError(fmt::format("{}: vertex {} of triangle {} has a coordinate that is not a finite number", name, v + 1,
                                     t + 1));
      auto [it, added] = index.emplace(x, static_cast<int>(s.points.size()));
      if (added) s.points.emplace_back(x[0], x[1], x[2]);
      tri[static_cast<std::size_t>(v)] = it->second;
    }
    s.triangles.push_back(tri);
  }
  return s;
}

}  // namespace stentsim::segmentation
