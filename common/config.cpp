#include "common/config.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <map>
#include <set>
#include <sstream>

#include "common/error.hpp"
#include "common/files.hpp"

namespace stentsim {
namespace {

std::string fmt_number(double v) { return fmt::format("{:g}", v); }

/// The most values a YAML file may hold with its aliases expanded. Aliases share
/// nodes, so ten of an anchor per level over nine levels load as a few dozen
/// nodes but are a billion values to every walk over them (this check, hashes,
/// emitters): such a file is refused rather than walked.
constexpr long kMaxYamlValues = 1000000;
/// yaml-cpp's parser stops at 2000 levels of nesting, but an alias inside its own
/// anchor (`x: &x [*x]`) loads as a cycle, endlessly deep to a walk.
constexpr int kMaxYamlDepth = 2000;

/// yaml-cpp keeps the first of two equal map keys and drops the second
/// silently; a case file must not mean something other than it says.
void reject_duplicate_keys(const YAML::Node& n, const std::filesystem::path& file, const std::string& path, long& values,
                           int depth = 0) {
  if (++values > kMaxYamlValues)
    throw InputError(fmt::format("{}: the YAML holds more than {} values once its aliases (*name) are expanded; write the "
                                 "values out instead of repeating anchors", file.string(), kMaxYamlValues));
  if (depth > kMaxYamlDepth)
    throw InputError(fmt::format("{}: the YAML nests deeper than {} levels (an alias inside its own anchor?)", file.string(),
                                 kMaxYamlDepth));
  if (n.IsMap()) {
    std::set<std::string> seen;
    for (const auto& kv : n) {
      const std::string k = kv.first.Scalar();
      const std::string kp = path.empty() ? k : path + "." + k;
      if (!seen.insert(k).second) {
        const auto m = kv.first.Mark();
        throw InputError(fmt::format("{}:{}:{}: {}: duplicate key '{}'", file.string(), m.line + 1, m.column + 1, kp, k));
      }
      reject_duplicate_keys(kv.second, file, kp, values, depth + 1);
    }
  } else if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) reject_duplicate_keys(n[i], file, fmt::format("{}[{}]", path, i), values, depth + 1);
  }
}

}  // namespace

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (min && (min_inclusive ? v < *min : v <= *min)) return false;
  if (max && (max_inclusive ? v > *max : v >= *max)) return false;
  return true;
}

std::string Range::describe() const {
  if (min && max) return fmt::format("in {}{}, {}{}", min_inclusive ? "[" : "(", fmt_number(*min), fmt_number(*max),
                                     max_inclusive ? "]" : ")");
  if (min) return fmt::format("{} {}", min_inclusive ? ">=" : ">", fmt_number(*min));
  if (max) return fmt::format("{} {}", max_inclusive ? "<=" : "<", fmt_number(*max));
  return "finite";
}

namespace {
// Control characters from a file (a pasted escape sequence, a stray NUL) shown as \xNN:
// raw in a message they would garble the terminal or the cohort summary.
std::string printable(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) out += fmt::format("\\x{:02x}", u);
    else out += c;
  }
  return out;
}
}  // namespace

ConfigMap ConfigMap::load(const std::filesystem::path& file) {
  files::require_regular_file(file, "YAML file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}:{}:{}: YAML syntax error: {}", file.string(), e.mark.line + 1, e.mark.column + 1,
                                 printable(e.msg)));
  }
  if (!root.IsMap()) throw InputError(fmt::format("{}: expected a YAML map at the top level", file.string()));
  long values = 0;
  reject_duplicate_keys(root, file, "", values);
  return ConfigMap(root, std::make_shared<const std::filesystem::path>(file), "");
}

ConfigMap ConfigMap::from_string(const std::string& text, const std::filesystem::path& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}:{}:{}: YAML syntax error: {}", file.string(), e.mark.line + 1, e.mark.column + 1,
                                 printable(e.msg)));
  }
  if (!root.IsMap()) throw InputError(fmt::format("{}: expected a YAML map at the top level", file.string()));
  long values = 0;
  reject_duplicate_keys(root, file, "", values);
  return ConfigMap(root, std::make_shared<const std::filesystem::path>(file), "");
}

ConfigMap::ConfigMap(YAML::Node node, std::shared_ptr<const std::filesystem::path> file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

std::string ConfigMap::where(const YAML::Node& n) const {
  const auto m = n.Mark();
  if (m.is_null()) return file_->string();
  return fmt::format("{}:{}:{}", file_->string(), m.line + 1, m.column + 1);
}

void ConfigMap::fail(const std::string& key, const std::string& message) const {
  YAML::Node at = (!key.empty() && node_[key]) ? node_[key] : node_;
  throw InputError(printable(
      fmt::format("{}: {}: {}", where(at), key.empty() ? (path_.empty() ? "(top level)" : path_) : key_path(key), message)));
}

bool ConfigMap::has(const std::string& key) const { return node_[key].IsDefined() && !node_[key].IsNull(); }

YAML::Node ConfigMap::scalar_node(const std::string& key) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (n && !n.IsNull() && !n.IsScalar()) fail(key, "expected a single value, got a " + std::string(n.IsMap() ? "map" : "list"));
  return n;
}

double ConfigMap::number(const std::string& key, std::optional<double> def, Range r) {
  YAML::Node n = scalar_node(key);
  double v;
  if (!n || n.IsNull()) {
    if (!def) fail(key, "required number is missing");
    v = *def;
  } else {
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      fail(key, fmt::format("expected a number, got '{}'", n.Scalar()));
    }
  }
  if (!r.contains(v)) fail(key, fmt::format("value {} is out of range: expected {}", fmt_number(v), r.describe()));
  return v;
}

int ConfigMap::integer(const std::string& key, std::optional<int> def, Range r) {
  YAML::Node n = scalar_node(key);
  int v;
  if (!n || n.IsNull()) {
    if (!def) fail(key, "required integer is missing");
    v = *def;
  } else {
    try {
      v = n.as<int>();
    } catch (const YAML::Exception&) {
      fail(key, fmt::format("expected an integer, got '{}'", n.Scalar()));
    }
  }
  if (!r.contains(v)) fail(key, fmt::format("value {} is out of range: expected {}", v, r.describe()));
  return v;
}

bool ConfigMap::boolean(const std::string& key, std::optional<bool> def) {
  YAML::Node n = scalar_node(key);
  if (!n || n.IsNull()) {
    if (!def) fail(key, "required true/false is missing");
    return *def;
  }
  try {
    return n.as<bool>();
  } catch (const YAML::Exception&) {
    fail(key, fmt::format("expected true or false, got '{}'", n.Scalar()));
  }
}

std::string ConfigMap::string(const std::string& key, std::optional<std::string> def) {
  YAML::Node n = scalar_node(key);
  if (!n || n.IsNull()) {
    if (!def) fail(key, "required text is missing");
    return *def;
  }
  return n.Scalar();
}

double ConfigMap::quantity(const std::string& key, const units::Dimension& dim, std::optional<double> def, Range r) {
  YAML::Node n = scalar_node(key);
  double v;
  if (!n || n.IsNull()) {
    if (!def) fail(key, "required value is missing: expected " + units::describe(dim));
    v = *def;
  } else {
    try {
      v = units::parse_quantity(n.Scalar(), dim);
    } catch (const std::invalid_argument& e) {
      fail(key, fmt::format("{}; expected {}", e.what(), units::describe(dim)));
    }
  }
  if (!r.contains(v)) fail(key, fmt::format("value {} (in project units) is out of range: expected {}", fmt_number(v), r.describe()));
  return v;
}

std::string ConfigMap::choice(const std::string& key, const std::vector<std::string>& options, std::optional<std::string> def) {
  std::string v = string(key, def);
  if (std::find(options.begin(), options.end(), v) == options.end()) {
    const std::string near = closest_name(options, v);
    fail(key, fmt::format("'{}' is not one of: {}{}", v, fmt::join(options, ", "),
                          near.empty() ? std::string() : fmt::format(" (did you mean '{}'?)", near)));
  }
  return v;
}

std::filesystem::path ConfigMap::path(const std::string& key, std::optional<std::filesystem::path> def) {
  YAML::Node n = scalar_node(key);
  std::filesystem::path p;
  if (!n || n.IsNull()) {
    if (!def) fail(key, "required file path is missing");
    p = *def;
  } else {
    p = n.Scalar();
  }
  if (p.is_relative()) p = file_->parent_path() / p;
  return std::filesystem::absolute(p).lexically_normal();
}

std::vector<double> ConfigMap::numbers(const std::string& key, std::size_t count, std::optional<std::vector<double>> def) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (!n || n.IsNull()) {
    if (!def) fail(key, fmt::format("required list of {} numbers is missing", count));
    return *def;
  }
  if (!n.IsSequence() || n.size() != count) fail(key, fmt::format("expected a list of {} numbers", count));
  std::vector<double> out;
  for (const auto& item : n) {
    try {
      out.push_back(item.as<double>());
    } catch (const YAML::Exception&) {
      fail(key, fmt::format("expected a number in the list, got '{}'", item.Scalar()));
    }
  }
  return out;
}

ConfigMap ConfigMap::map(const std::string& key) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (!n || n.IsNull()) return ConfigMap(YAML::Node(YAML::NodeType::Map), file_, key_path(key));
  if (!n.IsMap()) fail(key, "expected a map of settings");
  return ConfigMap(n, file_, key_path(key));
}

std::optional<ConfigMap> ConfigMap::optional_map(const std::string& key) {
  used_.insert(key);
  if (!has(key)) return std::nullopt;
  return map(key);
}

std::vector<ConfigMap> ConfigMap::map_list(const std::string& key) {
  used_.insert(key);
  YAML::Node n = node_[key];
  std::vector<ConfigMap> out;
  if (!n || n.IsNull()) return out;
  if (!n.IsSequence()) fail(key, "expected a list");
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsMap()) fail(key, fmt::format("item {} is not a map", i + 1));
    out.emplace_back(n[i], file_, fmt::format("{}[{}]", key_path(key), i));
  }
  return out;
}

void ConfigMap::finish() const {
  if (!node_.IsMap()) return;
  std::vector<std::string> known(used_.begin(), used_.end());
  for (const auto& kv : node_) {
    const std::string k = kv.first.Scalar();
    if (used_.count(k)) continue;
    std::string hint;
    std::size_t best = 3;
    for (const auto& cand : known) {
      std::size_t d = edit_distance(k, cand);
      if (d < best) best = d, hint = cand;
    }
    std::string msg = fmt::format("unknown key '{}'", k);
    if (!hint.empty()) msg += fmt::format(" (did you mean '{}'?)", hint);
    msg += fmt::format("; known keys here: {}", fmt::join(known, ", "));
    throw InputError(printable(fmt::format("{}: {}: {}", where(kv.first), key_path(k), msg)));
  }
}

namespace {
void emit_canonical(const YAML::Node& n, std::ostringstream& out) {
  switch (n.Type()) {
    case YAML::NodeType::Map: {
      std::map<std::string, YAML::Node> sorted;
      for (const auto& kv : n) sorted.emplace(kv.first.Scalar(), kv.second);
      out << '{';
      for (const auto& [k, v] : sorted) {
        out << k.size() << ':' << k << '=';
        emit_canonical(v, out);
        out << ';';
      }
      out << '}';
      break;
    }
    case YAML::NodeType::Sequence:
      out << '[';
      for (const auto& item : n) {
        emit_canonical(item, out);
        out << ',';
      }
      out << ']';
      break;
    case YAML::NodeType::Scalar:
      out << n.Scalar().size() << '"' << n.Scalar();
      break;
    default:
      out << '~';
  }
}
}  // namespace

std::string canonical_yaml(const YAML::Node& node) {
  std::ostringstream out;
  emit_canonical(node, out);
  return out.str();
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string closest_name(const std::vector<std::string>& candidates, const std::string& given) {
  std::string closest;
  for (const auto& c : candidates)
    if (closest.empty() || edit_distance(c, given) < edit_distance(closest, given)) closest = c;
  return !closest.empty() && edit_distance(closest, given) <= std::max<std::size_t>(2, given.size() / 3) ? closest : std::string();
}

}  // namespace stentsim
