#include "segmentation_io/image_header_geometry.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.hpp"

namespace stentsim::segmentation {
namespace {

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

/// Numbers of a NRRD vector list "(a,b,c) (d,e,f)"; "none" entries (non-spatial axes) count as missing.
std::vector<std::vector<double>> nrrd_vectors(const std::string& value, const std::string& where) {
  std::vector<std::vector<double>> out;
  std::size_t i = 0;
  while (i < value.size()) {
    if (value[i] == '(') {
      const auto close = value.find(')', i);
      if (close == std::string::npos) throw InputError(fmt::format("{}: unbalanced parenthesis", where));
      std::string inner = value.substr(i + 1, close - i - 1);
      for (char& c : inner)
        if (c == ',') c = ' ';
      std::istringstream in(inner);
      std::vector<double> v;
      double d;
      while (in >> d) v.push_back(d);
      if (!in.eof()) throw InputError(fmt::format("{}: '{}' is not a list of numbers", where, inner));
      out.push_back(v);
      i = close + 1;
    } else if (value.compare(i, 4, "none") == 0) {
      out.emplace_back();
      i += 4;
    } else {
      ++i;
    }
  }
  return out;
}

IndexToWorld checked(IndexToWorld g, const std::string& where) {
  const double det = g.step.determinant();
  const double scale = g.step.colwise().norm().prod();
  if (!std::isfinite(det) || std::abs(det) < 1e-9 * scale || scale == 0)
    throw InputError(fmt::format("{}: the index axes are degenerate (determinant {:.3g}); expected three independent "
                                 "directions", where, det));
  return g;
}

}  // namespace

std::optional<IndexToWorld> nrrd_index_to_world(const std::filesystem::path& file) {
  std::ifstream f(file, std::ios::binary);
  if (!f) throw InputError(fmt::format("{}: cannot be opened", file.string()));
  std::string line;
  std::optional<std::string> directions, origin;
  // The header ends at the first empty line (attached data follows it).
  for (int n = 0; std::getline(f, line) && n < 10000; ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;
    if (line[0] == '#') continue;
    const auto colon = line.find(": ");
    if (colon == std::string::npos || line.find(":=") < colon) continue;  // magic line or key/value pair
    const std::string key = trim(line.substr(0, colon)), value = trim(line.substr(colon + 2));
    if (key == "space directions") directions = value;
    else if (key == "space origin") origin = value;
  }
  if (!directions) return std::nullopt;
  const std::string where = file.string() + ": space directions";
  auto dirs = nrrd_vectors(*directions, where);
  std::vector<std::vector<double>> spatial;
  for (auto& d : dirs)
    if (!d.empty()) spatial.push_back(d);
  if (spatial.size() != 3 || spatial[0].size() != 3 || spatial[1].size() != 3 || spatial[2].size() != 3)
    throw InputError(fmt::format("{}: '{}' -- expected three 3-vectors, one per spatial axis", where, *directions));
  IndexToWorld g;
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c) g.step(c, a) = spatial[static_cast<std::size_t>(a)][static_cast<std::size_t>(c)];
  if (origin) {
    auto o = nrrd_vectors(*origin, file.string() + ": space origin");
    if (o.size() != 1 || o[0].size() != 3)
      throw InputError(fmt::format("{}: space origin: '{}' -- expected one 3-vector (x,y,z)", file.string(), *origin));
    g.origin = Eigen::Vector3d(o[0][0], o[0][1], o[0][2]);
  }
  return checked(g, where);
}

std::optional<IndexToWorld> metaimage_index_to_world(const std::filesystem::path& file) {
  std::ifstream f(file, std::ios::binary);
  if (!f) throw InputError(fmt::format("{}: cannot be opened", file.string()));
  std::string line;
  std::optional<std::vector<double>> matrix, offset, spacing;
  std::string matrix_key;
  auto numbers = [&](const std::string& key, const std::string& value, std::size_t n) {
    std::istringstream in(value);
    std::vector<double> v;
    double d;
    while (in >> d) v.push_back(d);
    if (!in.eof() || v.size() != n)
      throw InputError(fmt::format("{}: {} = '{}' -- expected {} numbers", file.string(), key, value, n));
    return v;
  };
  for (int n = 0; std::getline(f, line) && n < 10000; ++n) {
    const auto eq = line.find('=');
    if (eq == std::string::npos) continue;
    const std::string key = trim(line.substr(0, eq)), value = trim(line.substr(eq + 1));
    if (key == "TransformMatrix" || key == "Rotation" || key == "Orientation") {
      matrix = numbers(key, value, 9);
      matrix_key = key;
    } else if (key == "Offset" || key == "Origin" || key == "Position") {
      offset = numbers(key, value, 3);
    } else if (key == "ElementSpacing") {
      spacing = numbers(key, value, 3);
    } else if (key == "ElementDataFile") {
      break;  // the last header field; binary data may follow in a .mha
    }
  }
  if (!matrix) return std::nullopt;
  IndexToWorld g;
  const std::vector<double> h = spacing.value_or(std::vector<double>{1, 1, 1});
  for (int a = 0; a < 3; ++a) {
    Eigen::Vector3d row((*matrix)[3 * a], (*matrix)[3 * a + 1], (*matrix)[3 * a + 2]);  // direction of index axis a
    if (std::abs(row.norm() - 1) > 1e-4)
      throw InputError(fmt::format("{}: {}: row {} has length {:.6g}; expected unit direction cosines", file.string(),
                                   matrix_key, a + 1, row.norm()));
    g.step.col(a) = h[static_cast<std::size_t>(a)] * row;
  }
  if (offset) g.origin = Eigen::Vector3d((*offset)[0], (*offset)[1], (*offset)[2]);
  return checked(g, file.string() + ": " + matrix_key);
}

}  // namespace stentsim::segmentation
