#include "workflows/report/paper_targets.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <map>

#include "common/error.hpp"

namespace stentsim::workflows::report {

// Generated from paper_targets.yaml by EmbedPaperTargets.cmake.
const char* embedded_paper_targets();

namespace {

constexpr const char* kSource = "paper_targets.yaml (embedded)";

std::size_t indent_of(const std::string& line) {
  const auto p = line.find_first_not_of(' ');
  return p == std::string::npos ? line.size() : p;
}

// The comment of a YAML line ("" when none): text after the first '#' that
// starts a comment, i.e. is outside quotes and at the start or after a blank.
std::string trailing_comment(const std::string& line) {
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#' && (i == 0 || line[i - 1] == ' ' || line[i - 1] == '\t')) {
      auto s = line.substr(i + 1);
      const auto b = s.find_first_not_of(' ');
      return b == std::string::npos ? "" : s.substr(b);
    }
  }
  return "";
}

bool is_comment_only(const std::string& line) {
  const auto p = line.find_first_not_of(' ');
  return p != std::string::npos && line[p] == '#';
}

std::string key_of(const std::string& line) {
  const auto b = line.find_first_not_of(' ');
  const auto colon = line.find(':', b);
  return colon == std::string::npos ? "" : line.substr(b, colon - b);
}

// The comments on the entries of `section` (e.g. "results") of example `key`:
// the trailing comment of the entry's line, after the comment lines directly
// above it. yaml-cpp drops comments, and the targets file keeps its reasons there.
std::map<std::string, std::string> entry_comments(const std::string& text, const std::string& key, const std::string& section) {
  std::map<std::string, std::string> out;
  std::string example, current_section;
  std::vector<std::string> above;
  std::size_t start = 0;
  while (start <= text.size()) {
    auto end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    if (line.find_first_not_of(' ') == std::string::npos) {
      above.clear();
      if (end == text.size()) break;
      continue;
    }
    if (is_comment_only(line)) {
      above.push_back(trailing_comment(line));
      continue;
    }
    const std::size_t ind = indent_of(line);
    if (ind == 0) {
      example = key_of(line);
      current_section.clear();
    } else if (ind == 2) {
      current_section = key_of(line);
    }
    if (ind == 4 && example == key && current_section == section) {
      std::string c;
      for (const auto& a : above) c += (c.empty() ? "" : " ") + a;
      const auto t = trailing_comment(line);
      if (!t.empty()) c += (c.empty() ? "" : " ") + t;
      out[key_of(line)] = c;
    }
    above.clear();
    if (end == text.size()) break;
  }
  return out;
}

double number(const YAML::Node& n, const std::string& what, const std::string& source) {
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(fmt::format("{}: {} is '{}', expected a number", source, what, n.IsScalar() ? n.Scalar() : YAML::Dump(n)));
  }
}

YAML::Node load(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}: not valid YAML: {}", source, e.what()));
  }
}

}  // namespace

const std::string& paper_targets_text() {
  static const std::string text = embedded_paper_targets();
  return text;
}

std::vector<std::string> paper_case_keys(const std::string& text, const std::string& source) {
  std::vector<std::string> keys;
  for (const auto& kv : load(text, source)) keys.push_back(kv.first.as<std::string>());
  return keys;
}

PaperCase paper_case(const std::string& key) { return parse_paper_case(paper_targets_text(), key, kSource); }

PaperCase parse_paper_case(const std::string& text, const std::string& key, const std::string& source) {
  const YAML::Node root = load(text, source);
  const YAML::Node ex = root[key];
  if (!ex || !ex.IsMap())
    throw InputError(fmt::format("{}: no example '{}'; the examples are: {}", source, key,
                                 fmt::join(paper_case_keys(text, source), ", ")));
  PaperCase c;
  c.key = key;
  const auto comments = entry_comments(text, key, "results");
  if (const YAML::Node results = ex["results"]) {
    for (const auto& kv : results) {
      PaperResult r;
      r.name = kv.first.as<std::string>();
      const std::string what = fmt::format("{}.results.{}", key, r.name);
      const YAML::Node& v = kv.second;
      if (v.IsMap()) {
        if (v["paper"]) r.value = number(v["paper"], what + ".paper", source);
        if (v["tolerance"]) r.tolerance = number(v["tolerance"], what + ".tolerance", source);
        if (v["tolerance_abs"]) r.tolerance_abs = number(v["tolerance_abs"], what + ".tolerance_abs", source);
        r.report_only = v["report_only"] && v["report_only"].as<bool>();
        r.inconsistent = v["inconsistent"] && v["inconsistent"].as<bool>();
        if (!r.value) throw InputError(fmt::format("{}: {} has no 'paper' value", source, what));
      } else if (v.IsScalar()) {
        // A bare number is a value without a tolerance; anything else is the paper's words.
        try {
          r.value = v.as<double>();
        } catch (const YAML::Exception&) {
          r.text = v.as<std::string>();
        }
      } else {
        throw InputError(fmt::format("{}: {} is neither a number, a text nor a map with 'paper'", source, what));
      }
      if (auto it = comments.find(r.name); it != comments.end()) r.comment = it->second;
      c.results.push_back(std::move(r));
    }
  }
  if (ex["setup"] && ex["setup"]["pressure_max"]) {
    c.pressure_max = number(ex["setup"]["pressure_max"], key + ".setup.pressure_max", source);
    c.pressure_source = key + ".setup.pressure_max";
    c.pressure_comment = entry_comments(text, key, "setup")["pressure_max"];
  } else if (key != "free_expansion_straight" && root["free_expansion_straight"] && root["free_expansion_straight"]["setup"] &&
             root["free_expansion_straight"]["setup"]["pressure_max"]) {
    c.pressure_max = number(root["free_expansion_straight"]["setup"]["pressure_max"], "free_expansion_straight.setup.pressure_max", source);
    c.pressure_source = "free_expansion_straight.setup.pressure_max";
    c.pressure_shared = true;
    c.pressure_comment = entry_comments(text, "free_expansion_straight", "setup")["pressure_max"];
  }
  if (const YAML::Node rt = ex["run_time"]) {
    if (rt["paper_minutes"]) c.run_time_s = 60.0 * number(rt["paper_minutes"], key + ".run_time.paper_minutes", source);
    else if (rt["paper_hours"]) c.run_time_s = 3600.0 * number(rt["paper_hours"], key + ".run_time.paper_hours", source);
    if (rt["paper_processes"]) c.run_processes = static_cast<int>(number(rt["paper_processes"], key + ".run_time.paper_processes", source));
  }
  return c;
}

}  // namespace stentsim::workflows::report
