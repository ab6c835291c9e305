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

 private:
  void skip() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  std::string text_, file_;
  std::size_t at_ = 0;
};

// Cells as (count, ids...) lists or (5.1) OFFSETS + CONNECTIVITY; `add` gets each cell's ids.
template <class Add>
void read_cells(Tokens& t, const std::string& section, Add add) {
  const std::size_t n = t.count(section + " cell count");
  const long long size = t.integer(section + " size");
  std::vector<long long> ids;
  if (n == 0) return;
  std::string w = t.word(section + " cells");
  if (w == "OFFSETS") {
    t.word("the OFFSETS type");
    std::vector<long long> offsets(n);  // n is the number of offsets here (cells + 1)
    for (auto& o : offsets) o = t.integer(section + " offset");
    if (t.word("CONNECTIVITY") != "CONNECTIVITY") t.fail(section + ": CONNECTIVITY expected after the offsets");
    t.word("the CONNECTIVITY type");
    const std::size_t m = offsets.back() >= 0 ? static_cast<std::size_t>(offsets.back()) : 0;
    std::vector<long long> conn(m);
    for (auto& c : conn) c = t.integer(section + " point index");
    for (std::size_t c = 0; c + 1 < offsets.size(); ++c) {
      if (offsets[c] < 0 || offsets[c] > offsets[c + 1] || offsets[c + 1] > static_cast<long long>(conn.size()))
        t.fail(fmt::format("{}: offset {} is out of order or past the connectivity", section, c + 1));
      ids.assign(conn.begin() + offsets[c], conn.begin() + offsets[c + 1]);
      add(ids);
    }
    return;
  }
  long long used = 0;  // integers read: each cell's count and its ids
  for (std::size_t c = 0; c < n; ++c) {
    const long long k = t.to_integer(w, section + " point count");
    if (k < 0 || used + 1 + k > size) t.fail(fmt::format("{}: cell {} has {} points, past the section's size {}", section, c + 1, k, size));
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
  if (t.word("DATASET") != "DATASET" || t.word("the dataset type") != "POLYDATA")
    t.fail("not a legacy VTK file with POLYDATA (an unstructured grid or image is not a surface)");
  TriSurface s;
  bool have_points = false;
  while (!t.done()) {
    const std::string section = t.word("a section");
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
    } else if (section == "POINT_DATA" || section == "CELL_DATA" || section == "FIELD" || section == "METADATA") {
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
