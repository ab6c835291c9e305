#include "workflows/study/study_runs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <functional>
#include <stdexcept>
#include <unistd.h>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "workflows/study/input_paths.hpp"

namespace stentsim::study {
namespace {

const Knob& knob_named(const StudyConfig& s, const std::string& name) {
  for (const auto& k : s.knobs)
    if (k.name == name) return k;
  throw std::logic_error("no knob " + name);
}

RunSpec make_run(const StudyConfig& s, const std::map<std::string, int>& setting, FileHashes& hashes) {
  RunSpec r;
  r.setting = setting;
  r.input = YAML::Clone(s.base);
  r.ranks = s.base_ranks;
  std::string label;
  for (const auto& k : s.knobs) {
    auto it = setting.find(k.name);
    if (it == setting.end()) continue;
    label += fmt::format("{}{}={}", label.empty() ? "" : ", ", k.name, k.labels[static_cast<std::size_t>(it->second)]);
    const auto& values = k.values[static_cast<std::size_t>(it->second)];
    for (std::size_t j = 0; j < k.keys.size(); ++j) {
      if (k.keys[j] == "@ranks") {
        r.ranks = values[j].as<int>();
        continue;
      }
      try {
        set_dotted(r.input, k.keys[j], values[j]);
      } catch (const std::invalid_argument& e) {
        throw InputError(fmt::format("{}: knobs.{}.key '{}': {}", s.file.string(), k.name, k.keys[j], e.what()));
      }
    }
  }
  r.label = label.empty() ? "base" : label;
  YAML::Emitter em;
  em << r.input;
  r.input_text = std::string(em.c_str()) + "\n";
  std::string identity = canonical_yaml(r.input) + "\n#name " + s.base_name + "\n#ranks " + std::to_string(r.ranks);
  for (const auto& c : s.commands) identity += "\n#cmd " + fmt::format("{}", fmt::join(c, " "));
  // A run reads the files its input names: a changed mesh is a new run.
  for (const auto& f : referenced_files(r.input)) identity += "\n#file " + f.string() + " " + hashes.of(f);
  r.key = files::text_hash(identity).substr(0, 16);
  return r;
}

}  // namespace

StudyPlan plan_study(const StudyConfig& s) {
  StudyPlan p;
  std::map<std::string, std::size_t> by_key;
  FileHashes hashes;
  auto add = [&](const std::map<std::string, int>& setting) {
    RunSpec r = make_run(s, setting, hashes);
    auto [it, inserted] = by_key.try_emplace(r.key, p.runs.size());
    if (inserted) p.runs.push_back(std::move(r));
    else if (p.runs[it->second].setting.size() < setting.size()) {
      // The same input reached with more knobs named: keep the fuller label.
      p.runs[it->second].setting = r.setting;
      p.runs[it->second].label = r.label;
    }
    return it->second;
  };
  add({});
  for (const auto& k : s.knobs) {
    Line line{k.name, k.name, {}, {}};
    for (int i = 0; i < static_cast<int>(k.values.size()); ++i) {
      line.runs.push_back(add({{k.name, i}}));
      line.settings.push_back(i);
    }
    p.lines.push_back(std::move(line));
  }
  if (!s.grid.empty()) {
    // Full grid; one line per grid knob and combination of the others.
    std::vector<const Knob*> g;
    for (const auto& n : s.grid) g.push_back(&knob_named(s, n));
    std::map<std::string, int> setting;
    std::map<std::string, Line> grid_lines;
    std::function<void(std::size_t)> rec = [&](std::size_t d) {
      if (d == g.size()) {
        const std::size_t run = add(setting);
        for (const Knob* along : g) {
          std::string rest;
          for (const Knob* other : g)
            if (other != along)
              rest += fmt::format("{}{}={}", rest.empty() ? "" : ", ", other->name,
                                  other->labels[static_cast<std::size_t>(setting.at(other->name))]);
          const std::string label = along->name + " | " + rest;
          auto& line = grid_lines.try_emplace(label, Line{label, along->name, {}, {}}).first->second;
          line.runs.push_back(run);
          line.settings.push_back(setting.at(along->name));
        }
        return;
      }
      for (int i = 0; i < static_cast<int>(g[d]->values.size()); ++i) {
        setting[g[d]->name] = i;
        rec(d + 1);
      }
      setting.erase(g[d]->name);
    };
    rec(0);
    for (auto& [label, line] : grid_lines) {
      // Keep the knob's value order.
      std::vector<std::size_t> order(line.runs.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::sort(order.begin(), order.end(), [&](auto a, auto b) { return line.settings[a] < line.settings[b]; });
      Line sorted{line.label, line.knob, {}, {}};
      for (auto i : order) {
        sorted.runs.push_back(line.runs[i]);
        sorted.settings.push_back(line.settings[i]);
      }
      // A grid line with the same runs as a one-at-a-time line replaces it
      // (same points; the grid label says what the other knobs are).
      auto same = std::find_if(p.lines.begin(), p.lines.end(), [&](const Line& l) { return l.runs == sorted.runs; });
      if (same != p.lines.end()) *same = std::move(sorted);
      else p.lines.push_back(std::move(sorted));
    }
  }
  return p;
}

std::vector<std::vector<std::string>> run_commands(const StudyConfig& s, const RunSpec& run, const std::filesystem::path& dir,
                                                   const std::string& binary) {
  std::vector<std::vector<std::string>> out;
  for (const auto& c : s.commands) {
    std::vector<std::string> argv;
    if (run.ranks > 1) argv = {"mpirun", "--oversubscribe", "-np", std::to_string(run.ranks)};
    argv.push_back(binary);
    for (std::string a : c) {
      for (const auto& [ph, val] : {std::pair<std::string, std::string>{"{input}", (dir / s.base_name).string()},
                                    std::pair<std::string, std::string>{"{run}", dir.string()}})
        for (auto pos = a.find(ph); pos != std::string::npos; pos = a.find(ph, pos + val.size())) a.replace(pos, ph.size(), val);
      argv.push_back(a);
    }
    out.push_back(std::move(argv));
  }
  return out;
}

std::string setting_label(const StudyConfig& s, const RunSpec& run, const std::string& knob) {
  auto it = run.setting.find(knob);
  if (it == run.setting.end()) return "";
  return knob_named(s, knob).labels[static_cast<std::size_t>(it->second)];
}

std::optional<double> run_h(const StudyConfig& s, const RunSpec& run, const std::string& knob) {
  auto it = run.setting.find(knob);
  const Knob& k = knob_named(s, knob);
  if (it == run.setting.end() || k.h.empty()) return std::nullopt;
  return k.h[static_cast<std::size_t>(it->second)];
}

}  // namespace stentsim::study
