#include "workflows/study/study_config.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/units.hpp"
#include "workflows/study/input_paths.hpp"

namespace fs = std::filesystem;

namespace stentsim::study {
namespace {

std::vector<std::string> split_dots(const std::string& dotted) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const auto dot = dotted.find('.', start);
    parts.push_back(dotted.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  for (const auto& p : parts)
    if (p.empty()) throw std::invalid_argument("empty component in '" + dotted + "'");
  return parts;
}

std::optional<std::size_t> index_of(const std::string& part) {
  if (part.empty() || !std::all_of(part.begin(), part.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }))
    return std::nullopt;
  return static_cast<std::size_t>(std::stoul(part));
}

// Unknown keys are errors (ConfigMap::finish only knows keys read through its getters).
void only_keys(const ConfigMap& m, const std::set<std::string>& allowed) {
  for (const auto& kv : m.node()) {
    const auto key = kv.first.as<std::string>();
    if (!allowed.count(key)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      m.fail(key, fmt::format("unknown key (expected one of: {})", list));
    }
  }
}

std::string label_of(const std::vector<YAML::Node>& v) {
  std::string s;
  for (const auto& n : v) {
    if (!s.empty()) s += "x";
    s += n.IsScalar() ? n.Scalar() : YAML::Dump(n);
  }
  return s;
}

Knob read_knob(ConfigMap& k, std::set<std::string>& names) {
  only_keys(k, {"name", "key", "keys", "values", "labels", "h", "theoretical_order", "cost_exponent"});
  Knob knob;
  knob.name = k.string("name");
  if (!names.insert(knob.name).second) k.fail("name", "two knobs are called '" + knob.name + "'");
  if (k.has("key") == k.has("keys")) k.fail("key", "give exactly one of 'key' (one dotted path) or 'keys' (a list)");
  if (k.has("key")) knob.keys.push_back(k.string("key"));
  else {
    const YAML::Node ks = k.node()["keys"];
    if (!ks.IsSequence() || ks.size() == 0) k.fail("keys", "expected a non-empty list of dotted paths");
    for (const auto& n : ks) knob.keys.push_back(n.as<std::string>());
  }
  const YAML::Node vs = k.node()["values"];
  if (!vs || !vs.IsSequence() || vs.size() == 0) k.fail("values", "expected a non-empty list of settings");
  for (const auto& v : vs) {
    std::vector<YAML::Node> setting;
    if (knob.keys.size() == 1) setting.push_back(v);
    else {
      if (!v.IsSequence() || v.size() != knob.keys.size())
        k.fail("values", fmt::format("each setting must be a list of {} values, one per key", knob.keys.size()));
      for (const auto& x : v) setting.push_back(x);
    }
    knob.values.push_back(setting);
  }
  for (const auto& key : knob.keys)
    if (key == "@ranks")
      for (const auto& s : knob.values) {
        int r = 0;
        try {
          r = s.front().as<int>();
        } catch (const YAML::Exception&) {
        }
        if (r < 1) k.fail("values", "@ranks takes whole numbers >= 1");
      }
  if (k.has("labels")) {
    for (const auto& n : k.node()["labels"]) knob.labels.push_back(n.as<std::string>());
    if (knob.labels.size() != knob.values.size()) k.fail("labels", "needs one label per setting");
  } else {
    for (const auto& s : knob.values) knob.labels.push_back(label_of(s));
  }
  if (k.has("h")) {
    knob.h = k.numbers("h", knob.values.size());
    for (double h : knob.h)
      if (!(h > 0)) k.fail("h", "mesh sizes must be positive");
  }
  if (k.has("theoretical_order")) {
    const YAML::Node t = k.node()["theoretical_order"];
    if (t.IsMap()) {
      // Per line: {default: 2, tet10-curved: 3}; the setting labels are checked in load_study.
      for (const auto& kv : t) {
        double v = 0;
        try {
          v = kv.second.as<double>();
        } catch (const YAML::Exception&) {
          k.fail("theoretical_order", fmt::format("'{}': expected a number", kv.first.as<std::string>()));
        }
        if (!(v > 0)) k.fail("theoretical_order", fmt::format("'{}': orders must be positive", kv.first.as<std::string>()));
        const auto key = kv.first.as<std::string>();
        if (key == "default") knob.theoretical_order = v;
        else knob.theoretical_order_by_setting[key] = v;
      }
      if (knob.theoretical_order_by_setting.empty() && !knob.theoretical_order)
        k.fail("theoretical_order", "an empty map; give a number or {default: p, <setting label>: p, ...}");
    } else {
      knob.theoretical_order = k.number("theoretical_order", std::nullopt, Range::positive());
    }
    if (knob.h.empty()) k.fail("theoretical_order", "needs 'h' (the order is in h)");
  }
  knob.cost_exponent = k.number("cost_exponent", 0.0, Range::non_negative());
  if (knob.cost_exponent > 0 && knob.h.empty()) k.fail("cost_exponent", "needs 'h' (the cost is scaled by h)");
  return knob;
}

}  // namespace

void set_dotted(YAML::Node root, const std::string& dotted, const YAML::Node& value) {
  const auto parts = split_dots(dotted);
  YAML::Node node = root;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const bool last = i + 1 == parts.size();
    const std::string so_far = fmt::format("{}", fmt::join(parts.begin(), parts.begin() + static_cast<long>(i) + 1, "."));
    if (node.IsSequence()) {
      const auto idx = index_of(parts[i]);
      if (!idx || *idx >= node.size())
        throw std::invalid_argument(fmt::format("'{}': the list has {} entries", so_far, node.size()));
      if (last) {
        node[*idx] = value;
        return;
      }
      YAML::Node child = node[*idx];
      node.reset(child);
    } else if (node.IsMap()) {
      const YAML::Node& cnode = node;
      if (last) {
        node[parts[i]] = value;
        return;
      }
      if (!cnode[parts[i]]) throw std::invalid_argument(fmt::format("'{}' does not exist", so_far));
      YAML::Node child = node[parts[i]];
      node.reset(child);
    } else {
      throw std::invalid_argument(fmt::format("'{}' is not inside a map or list", so_far));
    }
  }
}

YAML::Node get_dotted(const YAML::Node& root, const std::string& dotted) {
  YAML::Node node = YAML::Clone(root);
  for (const auto& part : split_dots(dotted)) {
    YAML::Node child;
    if (node.IsSequence()) {
      const auto idx = index_of(part);
      if (!idx || *idx >= node.size()) return YAML::Node(YAML::NodeType::Undefined);
      child = node[*idx];
    } else if (node.IsMap()) {
      const YAML::Node& c = node;
      if (!c[part]) return YAML::Node(YAML::NodeType::Undefined);
      child = node[part];
    } else {
      return YAML::Node(YAML::NodeType::Undefined);
    }
    node.reset(child);
  }
  return node;
}

std::optional<double> theoretical_order_for(const StudyConfig& s, const Knob& along, const std::map<std::string, int>& setting) {
  for (const auto& other : s.knobs) {
    if (other.name == along.name) continue;
    std::optional<std::size_t> idx;
    if (auto it = setting.find(other.name); it != setting.end()) {
      idx = static_cast<std::size_t>(it->second);
    } else {
      // At the base's value: the setting whose values the base has.
      for (std::size_t j = 0; j < other.values.size() && !idx; ++j) {
        bool same = true;
        for (std::size_t q = 0; q < other.keys.size() && same; ++q) {
          if (other.keys[q] == "@ranks") same = other.values[j][q].as<int>() == s.base_ranks;
          else {
            const YAML::Node b = get_dotted(s.base, other.keys[q]);
            same = b.IsDefined() && YAML::Dump(b) == YAML::Dump(other.values[j][q]);
          }
        }
        if (same) idx = j;
      }
    }
    if (!idx) continue;
    if (auto t = along.theoretical_order_by_setting.find(other.labels[*idx]); t != along.theoretical_order_by_setting.end())
      return t->second;
  }
  return along.theoretical_order;
}

StudyConfig load_study(const fs::path& file) {
  ConfigMap root = ConfigMap::load(file);
  only_keys(root, {"name", "base", "overrides", "commands", "qoi", "reference", "error", "error_scale", "tolerance", "knobs", "grid", "ranks", "base_time"});
  StudyConfig c;
  c.file = file;
  c.name = root.string("name", file.stem().string());
  c.base_file = root.path("base");
  if (!fs::exists(c.base_file)) root.fail("base", fmt::format("file '{}' does not exist", c.base_file.string()));
  try {
    c.base = YAML::LoadFile(c.base_file.string());
  } catch (const YAML::Exception& e) {
    root.fail("base", fmt::format("cannot parse '{}': {}", c.base_file.string(), e.what()));
  }
  c.base_name = c.base_file.filename().string();
  // The runs' copies of the base live in their own folders: file names
  // relative to the base (its mesh, fibers, lumen) become absolute here;
  // names in overrides and knob values are relative to the study file.
  resolve_relative_files(c.base, c.base_file.parent_path());
  const fs::path study_folder = fs::absolute(file).parent_path();
  // overrides: {dotted.key: value} applied to the base for every run.
  if (root.has("overrides")) {
    const YAML::Node ov = root.node()["overrides"];
    if (!ov.IsMap()) root.fail("overrides", "expected a map of dotted keys to values");
    for (const auto& kv : ov) {
      const auto key = kv.first.as<std::string>();
      YAML::Node value = YAML::Clone(kv.second);
      resolve_relative_files(value, study_folder);
      try {
        set_dotted(c.base, key, value);
      } catch (const std::invalid_argument& e) {
        throw InputError(fmt::format("{}: overrides.{}: does not fit the base file {}: {}", file.string(), key,
                                     c.base_file.string(), e.what()));
      }
    }
  }
  if (root.has("commands")) {
    const YAML::Node cmds = root.node()["commands"];
    if (!cmds.IsSequence() || cmds.size() == 0) root.fail("commands", "expected a list of argument lists");
    for (const auto& cmd : cmds) {
      if (!cmd.IsSequence() || cmd.size() == 0) root.fail("commands", "each command is a non-empty list of arguments");
      std::vector<std::string> args;
      for (const auto& a : cmd) args.push_back(a.as<std::string>());
      c.commands.push_back(args);
    }
  } else {
    c.commands = {{"solve", "{input}", "--out", "{run}"}};
  }
  c.qoi = root.string("qoi");
  {
    ConfigMap ref = root.map("reference");
    only_keys(ref, {"type", "value", "knob"});
    const std::string type =
        ref.choice("type", {"tube_plane_strain", "beam_rollup", "beam_plastic_rollup", "beam_shooting", "value", "qoi_is_error",
                            "richardson"});
    using T = Reference::Type;
    c.reference.type = type == "tube_plane_strain"     ? T::tube_plane_strain
                       : type == "beam_rollup"         ? T::beam_rollup
                       : type == "beam_plastic_rollup" ? T::beam_plastic_rollup
                       : type == "beam_shooting"       ? T::beam_shooting
                       : type == "value"           ? T::value
                       : type == "qoi_is_error"    ? T::qoi_is_error
                                                   : T::richardson;
    if (c.reference.type == T::value) {
      const YAML::Node v = ref.node()["value"];
      if (!v) ref.fail("value", "a 'value' reference needs value: (a number or a list of numbers)");
      if (v.IsSequence())
        for (const auto& x : v) c.reference.value.push_back(x.as<double>());
      else c.reference.value.push_back(ref.number("value"));
    } else if (ref.has("value")) {
      ref.fail("value", "only a 'value' reference takes a value");
    }
    if (c.reference.type == T::richardson) c.reference.knob = ref.string("knob");
    else if (ref.has("knob")) ref.fail("knob", "only a 'richardson' reference names a knob");
  }
  const std::string err = root.choice("error", {"relative", "absolute"}, c.reference.type == Reference::Type::qoi_is_error ? "absolute" : "relative");
  c.relative_error = err == "relative";
  c.error_scale = root.number("error_scale", 1.0, Range::positive());
  if (root.has("tolerance")) c.tolerance = root.number("tolerance", std::nullopt, Range::positive());
  c.base_ranks = root.integer("ranks", 1, Range::between(1, 4096));
  if (root.has("base_time")) c.base_time_s = root.quantity("base_time", units::kTime, std::nullopt, Range::positive());
  std::set<std::string> names;
  for (auto& k : root.map_list("knobs")) c.knobs.push_back(read_knob(k, names));
  for (auto& k : c.knobs)
    for (auto& setting : k.values)
      for (auto& v : setting) {
        v = YAML::Clone(v);
        resolve_relative_files(v, study_folder);
      }
  if (c.knobs.empty()) root.fail("knobs", "a study needs at least one knob");
  for (const auto& k : c.knobs)
    for (const auto& key : k.keys) {
      if (key == "@ranks") continue;
      try {
        YAML::Node trial = YAML::Clone(c.base);
        set_dotted(trial, key, k.values.front().front());
      } catch (const std::invalid_argument& e) {
        throw InputError(fmt::format("{}: knobs.{}.key: '{}' does not fit the base file {}: {}", file.string(), k.name, key,
                                     c.base_file.string(), e.what()));
      }
    }
  if (root.has("grid")) {
    const YAML::Node g = root.node()["grid"];
    if (!g.IsSequence()) root.fail("grid", "expected a list of knob names");
    for (const auto& n : g) {
      const auto name = n.as<std::string>();
      if (!names.count(name)) root.fail("grid", fmt::format("'{}' is not a knob of this study", name));
      c.grid.push_back(name);
    }
    if (c.grid.size() < 2) root.fail("grid", "a grid needs at least two knobs");
  }
  // Per-setting orders must name a setting of another knob (a typo would
  // silently fall back to the default).
  for (const auto& k : c.knobs)
    for (const auto& [label, p] : k.theoretical_order_by_setting) {
      bool found = false;
      std::string all;
      for (const auto& other : c.knobs)
        if (other.name != k.name)
          for (const auto& l : other.labels) {
            found = found || l == label;
            all += (all.empty() ? "" : ", ") + l;
          }
      if (!found)
        throw InputError(fmt::format("{}: knobs.{}.theoretical_order: '{}' is neither 'default' nor a setting label of another knob "
                                     "(labels: {})", file.string(), k.name, label, all.empty() ? "none" : all));
    }
  if (c.reference.type == Reference::Type::richardson) {
    auto it = std::find_if(c.knobs.begin(), c.knobs.end(), [&](const Knob& k) { return k.name == c.reference.knob; });
    if (it == c.knobs.end()) root.fail("reference", fmt::format("reference.knob '{}' is not a knob of this study", c.reference.knob));
    if (it->h.empty() || it->h.size() < 3)
      root.fail("reference", fmt::format("Richardson extrapolation needs knob '{}' to give 'h' for at least three settings", it->name));
    // Issue 11: outside 0.5-1.5x the theoretical order the study reports "not
    // asymptotic" and does not extrapolate; without the order nothing is judged.
    if (!theoretical_order_for(c, *it, {}))
      throw InputError(fmt::format("{}: knobs.{}.theoretical_order: required with a 'richardson' reference (the observed order is "
                                   "judged against 0.5-1.5x it before extrapolating); give the discretisation's order in h, "
                                   "e.g. theoretical_order: 2",
                                   file.string(), it->name));
  }
  return c;
}

}  // namespace stentsim::study
