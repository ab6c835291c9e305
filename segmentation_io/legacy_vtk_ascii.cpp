#include "segmentation_io/legacy_vtk_ascii.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.hpp"

namespace stentsim::segmentation {
namespace {

class Tokens {
 public:
  Tokens(std::string text, std::size_t at, std::string file) : text_(std::move(text)), file_(std::move(file)), at_(at) {}
  bool done() {
    skip();
    return at_ >= text_.size();
  }
  std::string word(const std::string& what) {
    skip();
    if (at_ >= text_.size()) fail(fmt::format("the file ends where {} was expected (cut short?)", what));
    const std::size_t b = at_;
    while (at_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
    return text_.substr(b, at_ - b);
  }
  long long integer(const std::string& what) { return to_integer(word(what), what); }
  long long to_integer(const std::string& w, const std::string& what) const {
    long long v = 0;
    const auto [p, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
    if (ec != std::errc() || p != w.data() + w.size()) fail(fmt::format("{}: expected an integer, got '{}'", what, w.substr(0, 40)));
    return v;
  }
  double number(const std::string& what) {
    const std::string w = word(what);
    char* end = nullptr;
    const double v = std::strtod(w.c_str(), &end);
    if (end != w.c_str() + w.size()) fail(fmt::format("{}: expected a number, got '{}'", what, w.substr(0, 40)));
    if (!std::isfinite(v)) fail(fmt::format("{}: a coordinate that is not a finite number ('{}')", what, w.substr(0, 40)));
    return v;
  }
  /// A count from the file, checked against what is left of it (every item takes two bytes at least).
  std::size_t count(const std::string& what, long long items_per = 1) {
    const long long n = integer(what);
    if (n < 0 || static_cast<double>(n) * static_cast<double>(items_per) * 2 > static_cast<double>(text_.size() - at_) + 2)
      fail(fmt::format("{} = {} is more than the rest of the file can hold (cut short or damaged?)", what, n));
    return static_cast<std::size_t>(n);
  }
  [[noreturn]] void fail(const std::string& msg) const { throw InputError(fmt::format("{}: {}", file_, msg)); }
  /// Past the next blank line (the end of a METADATA block), or to the end of the file.
  void skip_block() {
    const std::size_t blank = text_.find("\n\n", at_), crlf = text_.find("\n\r\n", at_);
    const std::size_t end = std::min(blank, crlf);
    at_ = end == std::string::npos ? text_.size() : end + 2;
  }

 private:
  void skip() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  std::string text_, file_;
  std::size_t at_ = 0;
};

std::string upper(std::string w);

// FIELD name n, then n arrays "name components tuples type" and their values: skipped, counts checked.
void skip_field(Tokens& t) {
  t.word("the FIELD name");
  const std::size_t arrays = t.count("FIELD array count");
  for (std::size_t a = 0; a < arrays; ++a) {
    t.word("a FIELD array name");
    const std::size_t components = t.count("FIELD array components");
    const std::size_t tuples = t.count("FIELD array tuples", static_cast<long long>(components));
    t.word("a FIELD array type");
    for (std::size_t v = 0; v < components * tuples; ++v) t.word("a FIELD value");
  }
}

std::string upper(std::string w) {
  for (char& c : w) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return w;
}

// Cells as (count, ids...) lists or (5.1) OFFSETS + CONNECTIVITY; `add` gets each cell's ids.
template <class Add>
void read_cells(Tokens& t, const std::string& section, Add add) {
  const std::size_t n = t.count(section + " cell count");
  const long long size = static_cast<long long>(t.count(section + " size"));
  std::vector<long long> ids;
  if (n == 0) return;
  std::string w = t.word(section + " cells");
  if (upper(w) == "OFFSETS") {
    // 5.1: n offsets (cells + 1) from 0 to `size`, then `size` point indices.
    t.word("the OFFSETS type");
    std::vector<long long> offsets(n);
    for (auto& o : offsets) o = t.integer(section + " offset");
    if (offsets.front() != 0 || offsets.back() != size)
      t.fail(fmt::format("{}: the offsets run from {} to {}; expected 0 to the section's size {}", section, offsets.front(),
                         offsets.back(), size));
    for (std::size_t c = 0; c + 1 < offsets.size(); ++c)
      if (offsets[c] > offsets[c + 1]) t.fail(fmt::format("{}: offset {} is smaller than the one before it", section, c + 2));
    if (upper(t.word("CONNECTIVITY")) != "CONNECTIVITY") t.fail(section + ": CONNECTIVITY expected after the offsets");
    t.word("the CONNECTIVITY type");
    std::vector<long long> conn(static_cast<std::size_t>(size));
    for (auto& c : conn) c = t.integer(section + " point index");
    for (std::size_t c = 0; c + 1 < offsets.size(); ++c) {
      ids.assign(conn.begin() + offsets[c], conn.begin() + offsets[c + 1]);
      add(ids);
    }
    return;
  }
  long long used = 0;  // integers read: each cell's count and its ids
  for (std::size_t c = 0; c < n; ++c) {
    const long long k = t.to_integer(w, section + " point count");
    if (k < 0 || k > size - used - 1)  // never forms used + 1 + k (a damaged k must not overflow)
      t.fail(fmt::format("{}: cell {} has {} points, past the section's size {}", section, c + 1, k, size));
    ids.resize(static_cast<std::size_t>(k));
    for (auto& i : ids) i = t.integer(section + " point index");
    used += 1 + k;
    add(ids);
    if (c + 1 < n) w = t.word(section + " cells");
  }
  if (used != size) t.fail(fmt::format("{}: the cells hold {} integers, the header says {}", section, used, size));
}

}  // namespace

std::optional<TriSurface> read_legacy_vtk_ascii(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open the file", file.string()));
  std::string magic, title, format;
  std::getline(in, magic);
  std::getline(in, title);
  std::getline(in, format);
  if (magic.rfind("# vtk DataFile", 0) != 0)
    throw InputError(fmt::format("{}: not a legacy VTK file (its first line is not '# vtk DataFile Version ...')", file.string()));
  while (!format.empty() && std::isspace(static_cast<unsigned char>(format.back()))) format.pop_back();
  format = upper(format);
  if (format == "BINARY") return std::nullopt;
  if (format != "ASCII") throw InputError(fmt::format("{}: line 3 must be ASCII or BINARY", file.string()));
  in.clear();  // a file of three lines ends at EOF here
  const std::streamoff pos = in.tellg();
  std::stringstream ss;
  in.seekg(0);
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::size_t header = pos < 0 ? text.size() : std::min(static_cast<std::size_t>(pos), text.size());
  Tokens t(std::move(text), header, file.string());
  TriSurface s;
  std::string section = upper(t.word("DATASET"));
  if (section == "FIELD") {  // dataset-level field data may come first
    skip_field(t);
    section = upper(t.word("DATASET"));
  }
  if (section != "DATASET" || upper(t.word("the dataset type")) != "POLYDATA")
    t.fail("not a legacy VTK file with POLYDATA (an unstructured grid or image is not a surface)");
  bool have_points = false;
  while (!t.done()) {
    section = upper(t.word("a section"));
    if (section == "POINTS") {
      const std::size_t n = t.count("POINTS", 3);
      t.word("the POINTS type");
      s.points.resize(n);
      for (auto& p : s.points)
        for (int c = 0; c < 3; ++c) p[c] = t.number("POINTS");
      have_points = true;
    } else if (section == "POLYGONS" || section == "TRIANGLE_STRIPS") {
      const bool strip = section == "TRIANGLE_STRIPS";
      read_cells(t, section, [&](const std::vector<long long>& ids) {
        for (long long i : ids)
          if (i < 0 || i >= static_cast<long long>(s.points.size()))
            t.fail(fmt::format("{}: a cell refers to point {}, but the file has {} points", section, i, s.points.size()));
        for (std::size_t k = 2; k < ids.size(); ++k) {
          std::array<int, 3> tri = strip ? std::array<int, 3>{int(ids[k - 2]), int(ids[k - 1]), int(ids[k])}
                                         : std::array<int, 3>{int(ids[0]), int(ids[k - 1]), int(ids[k])};
          if (strip && k % 2 == 1) std::swap(tri[0], tri[1]);  // every other strip triangle turns
          s.triangles.push_back(tri);
        }
      });
    } else if (section == "VERTICES" || section == "LINES") {
      read_cells(t, section, [](const std::vector<long long>&) {});
    } else if (section == "METADATA") {
      t.skip_block();  // information keys (VTK 9 writes them after an array), up to a blank line
    } else if (section == "FIELD") {
      skip_field(t);
    } else if (section == "POINT_DATA" || section == "CELL_DATA") {
      break;  // attributes: not needed for the surface
    } else {
      t.fail(fmt::format("unknown section '{}' (expected POINTS, POLYGONS, TRIANGLE_STRIPS, VERTICES, LINES or POINT_DATA)",
                         section.substr(0, 40)));
    }
  }
  if (!have_points) t.fail("no POINTS section");
  return s;
}

}  // namespace stentsim::segmentation
