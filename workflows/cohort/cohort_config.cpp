#include "workflows/cohort/cohort_config.hpp"

#include <fmt/format.h>
#include <glob.h>
#include <unistd.h>

#include <algorithm>
#include <regex>
#include <sstream>
#include <set>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "pipeline/plan.hpp"
#include "workflows/case_config.hpp"
#include "workflows/case_stages.hpp"

namespace fs = std::filesystem;

namespace stentsim::workflows {
namespace {

/// Deep merge: maps merge key by key, anything else replaces; a null value
/// removes the key (as in JSON merge patch, RFC 7396), so a case can drop a
/// template section, e.g. `input: {phantom: null}` before giving a surface.
YAML::Node merge(const YAML::Node& base, const YAML::Node& over) {
  if (!over.IsMap() || !base.IsMap()) return YAML::Clone(over);
  YAML::Node out = YAML::Clone(base);
  for (const auto& kv : over) {
    const std::string k = kv.first.Scalar();
    if (kv.second.IsNull()) out.remove(k);
    else if (kv.second.IsMap()) out[k] = merge(out[k] && out[k].IsMap() ? out[k] : YAML::Node(YAML::NodeType::Map), kv.second);
    else out[k] = YAML::Clone(kv.second);
  }
  return out;
}

/// The dotted key whose (absolutized) scalar value is `value`, searched in a
/// merged case: it turns "<path>: input file of stage X not found" into the
/// case key the user wrote.
std::string key_holding(const YAML::Node& node, const std::string& value, const std::string& prefix = "") {
  if (!node.IsMap()) return "";
  for (const auto& kv : node) {
    const std::string k = prefix.empty() ? kv.first.Scalar() : prefix + "." + kv.first.Scalar();
    if (kv.second.IsScalar() && kv.second.Scalar() == value) return k;
    if (auto found = key_holding(kv.second, value, k); !found.empty()) return found;
  }
  return "";
}

/// Sets `dotted` ("input.surface.lumen") in a map, creating the maps on the way.
void set_dotted(YAML::Node node, const std::string& dotted, const std::string& value) {
  const auto dot = dotted.find('.');
  if (dot == std::string::npos) {
    node[dotted] = value;
    return;
  }
  const std::string head = dotted.substr(0, dot);
  if (!node[head] || !node[head].IsMap()) node[head] = YAML::Node(YAML::NodeType::Map);
  set_dotted(node[head], dotted.substr(dot + 1), value);
}

/// The files a glob pattern matches, sorted (glob(3): *, ?, [...] in any
/// path component; no **).
std::vector<fs::path> glob_files(const std::string& pattern) {
  glob_t g{};
  const int rc = ::glob(pattern.c_str(), 0, nullptr, &g);
  std::vector<fs::path> out;
  if (rc == 0)
    for (std::size_t i = 0; i < g.gl_pathc; ++i)
      if (fs::is_regular_file(g.gl_pathv[i])) out.emplace_back(g.gl_pathv[i]);
  ::globfree(&g);
  std::sort(out.begin(), out.end());
  return out;
}

/// A case id from a file name: the name without its extension ("p01.stl" ->
/// "p01"; "p01.nii.gz" -> "p01").
std::string id_from_file(const fs::path& f) {
  fs::path stem = f.stem();
  if (f.extension() == ".gz" || f.extension() == ".bz2" || f.extension() == ".xz") stem = stem.stem();
  return stem.string();
}

/// Relative file paths in the template are relative to the template's folder;
/// the merged case file lives elsewhere, so make the known path keys absolute.
void absolutize_paths(YAML::Node node, const fs::path& dir) {
  if (!node.IsMap()) return;
  for (auto kv : node) {
    const std::string k = kv.first.Scalar();
    if (kv.second.IsMap()) absolutize_paths(kv.second, dir);
    else if (kv.second.IsScalar() && (k == "file" || k == "lumen" || k == "wall" || k == "path" || k == "image")) {
      fs::path p(kv.second.Scalar());
      if (p.is_relative()) kv.second = (dir / p).lexically_normal().string();
    }
  }
}

std::string emit(const YAML::Node& n) {
  YAML::Emitter out;
  out << n;
  return std::string(out.c_str()) + "\n";
}

}  // namespace

YAML::Node merged_case(const CohortConfig& c, const CohortCase& k) {
  YAML::Node merged = merge(c.template_case, k.overrides);
  if (!merged["name"]) merged["name"] = k.id;
  merged["name"] = k.id;
  merged["work_dir"] = "work";
  return merged;
}

CohortConfig load_cohort(const fs::path& file) {
  ConfigMap top = ConfigMap::load(file);
  CohortConfig c;
  c.file = fs::absolute(file).lexically_normal();
  c.name = top.string("name", file.stem().string());
  c.work_dir = top.path("work_dir", fs::path(file.stem().string() + ".work"));
  c.workers = top.integer("workers", 0, Range::between(0, 1024));
  c.ranks_per_case = top.integer("ranks_per_case", 1, Range::between(1, 1024));
  c.backend = top.choice("backend", {"local", "slurm"}, std::string("local"));
  if (auto sm = top.optional_map("slurm")) {
    c.slurm.partition = sm->string("partition", std::string());
    c.slurm.time_limit = sm->string("time_limit", std::string());
    c.slurm.memory = sm->string("memory", std::string());
    c.slurm.cpus_per_case = sm->integer("cpus_per_case", 1, Range::between(1, 1024));
    c.slurm.poll_interval_s = sm->number("poll_interval_s", 1.0, Range::between(0.05, 600));
    c.slurm.queue_patience_s = sm->number("queue_patience_s", 300.0, Range::between(0, 86400));
    // One string of options separated by spaces (no shell quoting is applied).
    std::istringstream extra(sm->string("extra_sbatch_options", std::string()));
    for (std::string opt; extra >> opt;) {
      if (opt.rfind("-", 0) != 0)
        sm->fail("extra_sbatch_options", fmt::format("'{}' is not an sbatch option (options start with '-')", opt));
      c.slurm.extra_options.push_back(opt);
    }
    sm->finish();
  }
  if (top.has("template") && top.has("template_case")) top.fail("template", "give either 'template' (a case file) or 'template_case' (inline), not both");
  if (top.has("template")) {
    const fs::path t = top.path("template");
    c.template_case = ConfigMap::load(t).node();
    c.template_dir = t.parent_path();
  } else {
    auto inline_case = top.map("template_case");
    if (!top.has("template_case")) top.fail("", "required 'template' (a case file) or 'template_case' is missing");
    c.template_case = YAML::Clone(inline_case.node());
    c.template_dir = c.file.parent_path();
  }
  absolutize_paths(c.template_case, c.template_dir);
  std::set<std::string> ids;
  const std::regex id_ok("[A-Za-z0-9][A-Za-z0-9_.-]*");
  for (auto& k : top.map_list("cases")) {
    CohortCase cc;
    cc.id = k.string("id");
    if (!std::regex_match(cc.id, id_ok)) k.fail("id", fmt::format("'{}' is not a valid case id (letters, digits, '_', '.', '-')", cc.id));
    if (!ids.insert(cc.id).second) k.fail("id", fmt::format("duplicate case id '{}'", cc.id));
    if (k.has("expect_failure")) cc.expect_failure = k.choice("expect_failure", all_stage_names());
    cc.overrides = YAML::Clone(k.map("overrides").node());
    absolutize_paths(cc.overrides, c.file.parent_path());
    k.finish();
    c.cases.push_back(std::move(cc));
  }
  // cases_from: one case per file a glob matches (issue 10: "every STL in a
  // folder"); a single map or a list of them.
  std::vector<ConfigMap> globs;
  if (top.has("cases_from") && top.node()["cases_from"].IsMap()) globs.push_back(top.map("cases_from"));
  else globs = top.map_list("cases_from");
  for (auto& g : globs) {
    const std::string pattern_text = g.string("glob");
    fs::path pattern(pattern_text);
    if (pattern.is_relative()) pattern = c.file.parent_path() / pattern;
    const std::string key = g.string("key");
    if (!std::regex_match(key, std::regex("[A-Za-z_][A-Za-z0-9_]*(\\.[A-Za-z_][A-Za-z0-9_]*)*")))
      g.fail("key", fmt::format("'{}' is not a dotted case key such as input.surface.lumen", key));
    YAML::Node common = YAML::Clone(g.map("overrides").node());
    absolutize_paths(common, c.file.parent_path());
    std::optional<std::string> expect;
    if (g.has("expect_failure")) expect = g.choice("expect_failure", all_stage_names());
    g.finish();
    const auto files = glob_files(pattern.lexically_normal().string());
    if (files.empty()) g.fail("glob", fmt::format("'{}' matches no file ({})", pattern_text, pattern.lexically_normal().string()));
    for (const auto& f : files) {
      CohortCase cc;
      cc.id = id_from_file(f);
      if (!std::regex_match(cc.id, id_ok))
        g.fail("glob", fmt::format("{}: '{}' is not a valid case id (letters, digits, '_', '.', '-'); rename the file",
                                   f.string(), cc.id));
      if (!ids.insert(cc.id).second)
        g.fail("glob", fmt::format("duplicate case id '{}' (from {}): case ids must be unique across cases and cases_from",
                                   cc.id, f.string()));
      cc.overrides = YAML::Clone(common);
      set_dotted(cc.overrides, key, fs::absolute(f).lexically_normal().string());
      cc.expect_failure = expect;
      cc.origin = fmt::format("{} from {}", key, f.string());
      c.cases.push_back(std::move(cc));
    }
  }
  if (c.cases.empty()) top.fail("cases", "a cohort needs at least one case (cases: or cases_from:)");
  top.finish();
  // Validate every merged case now, so nothing runs when one is wrong.
  const fs::path check_dir = fs::temp_directory_path() / fmt::format("stentsim-cohort-check-{}", ::getpid());
  for (auto& k : c.cases) {
    const fs::path f = check_dir / (k.id + ".yaml");
    files::write_atomic(f, emit(merged_case(c, k)));
    try {
      // The case file and its plan, as `stentsim run` builds them: the plan
      // checks that every external input file (input.surface.lumen, ...) exists.
      const CaseConfig cc = load_case(f);
      pipeline::Plan plan(stages_for(cc), cc.work_dir);
      k.stages.clear();
      for (const auto& st : stages_for(cc)) k.stages.push_back(st.name);
    } catch (const InputError& e) {
      fs::remove_all(check_dir);
      std::string msg = e.what();
      const std::string prefix = f.string() + ":";
      // The line numbers refer to the merged file, not the cohort file: drop them.
      if (msg.rfind(prefix, 0) == 0) msg = std::regex_replace(msg.substr(prefix.size()), std::regex("^[0-9]+:[0-9]+: "), "");
      // A missing input file: name the case key that gave it.
      static const std::regex missing("^(.*): input file of stage '([^']+)' not found$");
      std::smatch m;
      if (std::regex_match(msg, m, missing)) {
        const std::string key = key_holding(merged_case(c, k), m[1].str());
        msg = fmt::format("{}input file not found: {} (needed by stage {})", key.empty() ? "" : key + ": ", m[1].str(),
                          m[2].str());
      }
      throw InputError(fmt::format("{}: case '{}'{}: {}", c.file.string(), k.id, k.origin.empty() ? "" : " (" + k.origin + ")", msg));
    }
  }
  fs::remove_all(check_dir);
  return c;
}

namespace {
std::string case_file_text(const CohortConfig& c, const CohortCase& k) {
  return "# generated by stentsim cohort from " + c.file.string() + "; do not edit\n" + emit(merged_case(c, k));
}
}  // namespace

CaseConfig cohort_case_config(const CohortConfig& c, const CohortCase& k) {
  const fs::path f = c.work_dir / k.id / "case.yaml";
  std::error_code ec;
  if (fs::exists(f, ec) && files::read_text(f) == case_file_text(c, k)) return load_case(f);
  YAML::Node merged = merged_case(c, k);
  merged["work_dir"] = (c.work_dir / k.id / "work").string();
  const fs::path tmp = fs::temp_directory_path() / fmt::format("stentsim-cohort-status-{}", ::getpid());
  const fs::path tf = tmp / (k.id + ".yaml");
  files::write_atomic(tf, emit(merged));
  try {
    CaseConfig cc = load_case(tf);
    fs::remove_all(tmp, ec);
    return cc;
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
}

std::vector<fs::path> materialize_cases(const CohortConfig& c) {
  std::vector<fs::path> out;
  for (const auto& k : c.cases) {
    const fs::path f = c.work_dir / k.id / "case.yaml";
    const std::string text = case_file_text(c, k);
    if (!fs::exists(f) || files::read_text(f) != text) files::write_atomic(f, text);
    out.push_back(f);
  }
  return out;
}

}  // namespace stentsim::workflows
