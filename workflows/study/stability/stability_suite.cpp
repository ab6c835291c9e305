#include "workflows/study/stability/stability_suite.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <set>
#include <sstream>
#include <stdexcept>

#include "common/config.hpp"
#include "common/error.hpp"

namespace fs = std::filesystem;

namespace stentsim::study {

double StabilitySuite::limit_s(const StabilityCase& c) const { return std::max(min_limit_s, limit_factor * c.time_s); }

void set_dotted_key(YAML::Node root, const std::string& dotted, const YAML::Node& value) {
  std::vector<std::string> parts;
  std::stringstream ss(dotted);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  if (parts.empty() || std::any_of(parts.begin(), parts.end(), [](const std::string& p) { return p.empty(); }))
    throw std::invalid_argument(fmt::format("'{}' is not a dotted key (a.b.0.c)", dotted));
  // YAML::Node assignment rebinds handles, so walk by index into a vector of nodes.
  std::vector<YAML::Node> path{root};
  std::string so_far;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    const YAML::Node& cur = path.back();
    so_far += (so_far.empty() ? "" : ".") + parts[i];
    YAML::Node next;
    if (cur.IsSequence()) {
      std::size_t k = 0;
      try {
        k = std::stoul(parts[i]);
      } catch (const std::exception&) {
        throw std::invalid_argument(fmt::format("'{}' is a list: expected an index", so_far));
      }
      if (k >= cur.size()) throw std::invalid_argument(fmt::format("'{}': the list has {} items", so_far, cur.size()));
      next = cur[k];
    } else if (cur.IsMap() && cur[parts[i]]) {
      next = cur[parts[i]];
    } else {
      throw std::invalid_argument(fmt::format("'{}' does not exist", so_far));
    }
    path.push_back(next);
  }
  YAML::Node last = path.back();
  const std::string& key = parts.back();
  if (last.IsSequence()) {
    std::size_t k = 0;
    try {
      k = std::stoul(key);
    } catch (const std::exception&) {
      throw std::invalid_argument(fmt::format("'{}' ends in a list: expected an index", dotted));
    }
    if (k >= last.size()) throw std::invalid_argument(fmt::format("'{}': the list has {} items", dotted, last.size()));
    last[k] = YAML::Clone(value);
  } else if (last.IsMap()) {
    last[key] = YAML::Clone(value);
  } else {
    throw std::invalid_argument(fmt::format("'{}': the parent is not a map or list", dotted));
  }
}

StabilitySuite load_stability_suite(const fs::path& file) {
  ConfigMap root = ConfigMap::load(file);
  StabilitySuite s;
  s.file = file;
  s.name = root.string("name", file.stem().string());
  s.limit_factor = root.number("limit_factor", 10.0, Range::positive());
  s.min_limit_s = root.quantity("min_limit", units::kTime, 60.0, Range::positive());
  std::set<std::string> ids;
  for (auto& c : root.map_list("cases")) {
    StabilityCase k;
    k.id = c.string("id");
    if (k.id.empty() || k.id.find_first_of("/\\ ") != std::string::npos) c.fail("id", "expected a name without spaces or slashes");
    if (!ids.insert(k.id).second) c.fail("id", fmt::format("'{}' is used twice", k.id));
    k.subset = c.choice("subset", {"quick", "all"}, "all");
    const int kinds = int(c.has("scene")) + int(c.has("case")) + int(c.has("exec"));
    if (kinds != 1) c.fail("", "expected exactly one of scene, case, exec");
    if (c.has("scene")) {
      k.kind = StabilityCase::Kind::scene;
      k.input = c.path("scene");
    } else if (c.has("case")) {
      k.kind = StabilityCase::Kind::case_file;
      k.input = c.path("case");
      k.until = c.string("until", "");
      k.failed_stage = c.string("failed_stage", "");
    } else {
      k.kind = StabilityCase::Kind::exec;
      const YAML::Node n = c.node()["exec"];
      if (!n.IsSequence() || n.size() == 0) c.fail("exec", "expected a list: the program and its arguments");
      for (const auto& a : n) k.exec.push_back(a.as<std::string>());
    }
    if (k.kind != StabilityCase::Kind::exec && !fs::exists(k.input))
      c.fail(k.kind == StabilityCase::Kind::scene ? "scene" : "case", fmt::format("file {} does not exist", k.input.string()));
    if (c.has("set")) {
      const YAML::Node n = c.node()["set"];
      if (!n.IsMap()) c.fail("set", "expected a map of dotted keys to values");
      for (const auto& kv : n) k.set.emplace_back(kv.first.as<std::string>(), kv.second);
      // each dotted key must apply to the input: checked now, not mid-suite
      if (k.kind != StabilityCase::Kind::exec) {
        YAML::Node probe = YAML::LoadFile(k.input.string());
        for (const auto& [key, value] : k.set) {
          try {
            set_dotted_key(probe, key, value);
          } catch (const std::invalid_argument& e) {
            c.fail("set", fmt::format("{} (in {})", e.what(), k.input.filename().string()));
          }
        }
      }
    }
    if (c.has("args")) {
      const YAML::Node n = c.node()["args"];
      if (!n.IsSequence()) c.fail("args", "expected a list of command-line arguments");
      for (const auto& a : n) k.args.push_back(a.as<std::string>());
    }
    k.time_s = c.quantity("time", units::kTime, 6.0, Range::positive());
    const std::string expect =
        c.choice("expect", {"converged", "failed cleanly", "converged or failed cleanly", "rejected"}, "converged");
    k.expect = expect == "converged or failed cleanly" ? std::vector<std::string>{"converged", "failed cleanly"}
                                                        : std::vector<std::string>{expect};
    k.message = c.string("message", "");
    if (auto cmp = c.optional_map("compare")) {
      StabilityCase::Compare m;
      m.case_id = cmp->string("case");
      if (!ids.count(m.case_id)) cmp->fail("case", fmt::format("'{}' is not a case listed before this one", m.case_id));
      m.qoi = cmp->string("qoi");
      m.tolerance = cmp->number("tolerance", std::nullopt, Range::non_negative());
      cmp->finish();
      k.compare = m;
    }
    // lists and maps above are read from the node directly: check the keys here
    static const std::set<std::string> known{"id", "subset", "scene", "case", "exec", "until", "failed_stage", "set",
                                             "args", "time", "expect", "message", "compare"};
    for (const auto& kv : c.node())
      if (!known.count(kv.first.as<std::string>()))
        c.fail(kv.first.as<std::string>(), "unknown key (expected one of id, subset, scene, case, exec, until, failed_stage, "
                                           "set, args, time, expect, message, compare)");
    s.cases.push_back(std::move(k));
  }
  if (s.cases.empty()) root.fail("cases", "expected at least one case");
  root.finish();
  return s;
}

}  // namespace stentsim::study
