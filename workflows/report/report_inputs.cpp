#include "workflows/report/report_inputs.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <set>

#include "common/error.hpp"
#include "common/files.hpp"

namespace fs = std::filesystem;

namespace stentsim::workflows::report {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const auto pos = line.find(sep, start);
    cells.push_back(trim(line.substr(start, pos == std::string::npos ? std::string::npos : pos - start)));
    if (pos == std::string::npos) break;
    start = pos + 1;
  }
  return cells;
}

std::optional<double> parse_number(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size()) return std::nullopt;
  return v;
}

// The value of attribute `name` inside one XML start tag, if present.
std::optional<std::string> attribute(const std::string& tag, const std::string& name) {
  std::size_t pos = 0;
  while ((pos = tag.find(name, pos)) != std::string::npos) {
    const bool starts_word = pos > 0 && std::isspace(static_cast<unsigned char>(tag[pos - 1]));
    std::size_t p = pos + name.size();
    while (p < tag.size() && std::isspace(static_cast<unsigned char>(tag[p]))) ++p;
    if (starts_word && p < tag.size() && tag[p] == '=') {
      ++p;
      while (p < tag.size() && std::isspace(static_cast<unsigned char>(tag[p]))) ++p;
      if (p < tag.size() && (tag[p] == '"' || tag[p] == '\'')) {
        const auto close = tag.find(tag[p], p + 1);
        if (close != std::string::npos) return tag.substr(p + 1, close - p - 1);
      }
      return std::nullopt;
    }
    pos += name.size();
  }
  return std::nullopt;
}

}  // namespace

const std::vector<double>& History::column(const std::string& name) const {
  static const std::vector<double> none;
  auto it = values.find(name);
  return it == values.end() ? none : it->second;
}

std::vector<std::string> History::columns_like(const std::string& prefix, const std::string& suffix) const {
  std::vector<std::string> out;
  for (const auto& c : columns)
    if (c.size() > prefix.size() + suffix.size() && c.compare(0, prefix.size(), prefix) == 0 &&
        c.compare(c.size() - suffix.size(), suffix.size(), suffix) == 0)
      out.push_back(c);
  return out;
}

double History::sum(const std::string& name) const {
  double s = 0;
  for (double v : column(name))
    if (std::isfinite(v)) s += v;
  return s;
}

const std::vector<std::string>& required_history_columns() {
  static const std::vector<std::string> cols = {"step",       "time",        "dt",         "load_factor",
                                                "newton_iterations", "linear_iterations", "step_cuts",
                                                "wall_time_s", "assembly_s", "linear_solve_s"};
  return cols;
}

History read_history(const fs::path& file) {
  if (!fs::exists(file))
    throw InputError(fmt::format("{}: missing; the solve stage writes it (one row per converged step)", file.string()));
  const std::string text = files::read_text(file);
  History h;
  h.file = file;
  std::size_t line_no = 0, start = 0;
  bool header_seen = false;
  while (start < text.size()) {
    auto end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    ++line_no;
    if (trim(line).empty()) continue;  // a trailing newline or blank line carries no step
    const auto cells = split(line, ',');
    if (!header_seen) {
      std::set<std::string> seen;
      for (const auto& c : cells) {
        if (c.empty()) throw InputError(fmt::format("{}:{}: the header has an empty column name", file.string(), line_no));
        if (!seen.insert(c).second)
          throw InputError(fmt::format("{}:{}: column '{}' appears twice in the header", file.string(), line_no, c));
      }
      std::vector<std::string> missing;
      for (const auto& r : required_history_columns())
        if (!seen.count(r)) missing.push_back(r);
      if (!missing.empty())
        throw InputError(fmt::format("{}:{}: the header lacks the column(s) {} (expected at least: {})", file.string(), line_no,
                                     fmt::join(missing, ", "), fmt::join(required_history_columns(), ",")));
      h.columns = cells;
      for (const auto& c : cells) h.values[c];
      header_seen = true;
      continue;
    }
    if (cells.size() != h.columns.size())
      throw InputError(fmt::format("{}:{}: {} values, but the header has {} columns", file.string(), line_no, cells.size(),
                                   h.columns.size()));
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const auto v = parse_number(cells[i]);
      if (!v)
        throw InputError(fmt::format("{}:{}: column '{}' holds '{}', which is not a number", file.string(), line_no, h.columns[i],
                                     cells[i]));
      h.values[h.columns[i]].push_back(*v);
    }
    ++h.rows;
  }
  if (!header_seen) throw InputError(fmt::format("{}: empty; expected a header line and one row per converged step", file.string()));
  return h;
}

Summary read_summary(const fs::path& file, const std::string& written_by) {
  if (!fs::exists(file)) throw InputError(fmt::format("{}: missing; {} writes it", file.string(), written_by));
  return Summary::read(file);  // names the file when it is damaged
}

std::vector<std::pair<std::string, std::string>> read_summary_notes(const fs::path& file) {
  std::vector<std::pair<std::string, std::string>> out;
  try {
    const YAML::Node root = YAML::LoadFile(file.string());
    const YAML::Node notes = root["notes"];
    if (!notes) return out;
    if (notes.IsMap()) {
      for (const auto& kv : notes) out.emplace_back(kv.first.as<std::string>(), kv.second.IsScalar() ? kv.second.as<std::string>() : YAML::Dump(kv.second));
    } else if (notes.IsSequence()) {
      for (const auto& n : notes) out.emplace_back("", n.IsScalar() ? n.as<std::string>() : YAML::Dump(n));
    } else if (notes.IsScalar()) {
      out.emplace_back("", notes.as<std::string>());
    }
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}: not a valid summary.yaml: {}", file.string(), e.what()));
  }
  return out;
}

std::vector<PvdFrame> read_pvd(const fs::path& file) {
  const std::string text = files::read_text(file);
  std::vector<PvdFrame> frames;
  std::size_t pos = 0;
  while ((pos = text.find("<DataSet", pos)) != std::string::npos) {
    const auto end = text.find('>', pos);
    if (end == std::string::npos) throw InputError(fmt::format("{}: a <DataSet> tag is not closed", file.string()));
    const std::string tag = text.substr(pos, end - pos);
    pos = end;
    PvdFrame f;
    const auto t = attribute(tag, "timestep");
    const auto ft = t ? parse_number(*t) : std::nullopt;
    if (!ft || !std::isfinite(*ft))
      throw InputError(fmt::format("{}: a <DataSet> has timestep '{}', expected a number", file.string(), t.value_or("")));
    f.time = *ft;
    const auto name = attribute(tag, "name");
    const auto part = attribute(tag, "part");
    f.part = name && !name->empty() ? *name : part.value_or("");
    const auto rel = attribute(tag, "file");
    if (!rel || rel->empty()) throw InputError(fmt::format("{}: a <DataSet> at timestep {} names no file", file.string(), *t));
    f.file = *rel;
    frames.push_back(std::move(f));
  }
  return frames;
}

std::optional<std::string> inflation_pressure_column(const History& h) {
  if (h.has("pressure_inflation")) return std::string("pressure_inflation");
  for (const auto& c : h.columns_like("pressure_", ""))
    if (c != "pressure_diastolic") return c;
  return std::nullopt;
}

std::size_t inflation_end(const std::vector<double>& p) {
  double peak = 0;
  std::size_t first = p.size();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::isfinite(p[i]) && p[i] > peak) {
      peak = p[i];
      first = i;
    }
  if (first == p.size()) return 0;
  // A hold at the peak belongs to the inflation; the tolerance absorbs the
  // ten significant digits history.csv is written with.
  std::size_t end = first + 1;
  while (end < p.size() && std::isfinite(p[end]) && std::abs(p[end] - peak) <= 1e-9 * peak) ++end;
  return end;
}

}  // namespace stentsim::workflows::report
