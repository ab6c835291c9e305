#include "workflows/study/stability/stability_command.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "common/error.hpp"
#include "common/child_process.hpp"
#include "workflows/study/stability/stability_runner.hpp"

namespace fs = std::filesystem;

namespace stentsim::study {
namespace {

constexpr const char* kUsage =
    "usage: stentsim study stability [SUITE.yaml] [--out DIR] [--subset quick|all] [--cases ID,...] [--binary PATH]\n"
    "  SUITE.yaml   the suite (default examples/studies/stability/stability.yaml)\n"
    "  --out DIR    where cases run and stability.csv / stability.md go (default <suite>.work)\n"
    "  --subset     quick: the cases marked 'subset: quick' (a few minutes); all (default): every case\n"
    "  --cases      only these case ids\n"
    "  --binary     the stentsim executable the cases run (default: this one)\n";

/// This executable, or empty when unknown (the suite search then starts at the working folder).
fs::path self_executable() {
  try {
    return process::self_executable();
  } catch (const ComputeError&) {
    return {};
  }
}

fs::path default_suite() {
  const fs::path rel = fs::path("examples") / "studies" / "stability" / "stability.yaml";
  if (fs::exists(rel)) return rel;
  // from the executable (build/workflows/stentsim) up to the source tree
  for (fs::path p = self_executable().parent_path(); !p.empty() && p != p.root_path(); p = p.parent_path())
    if (fs::exists(p / rel)) return p / rel;
  throw InputError(fmt::format("stability: no suite file given and {} not found from here or from the executable's folder",
                               rel.string()));
}

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string w; std::getline(ss, w, ',');)
    if (!w.empty()) out.push_back(w);
  return out;
}

}  // namespace

int run_stability_command(const std::vector<std::string>& args) {
  try {
    fs::path suite_file, out_dir;
    StabilityOptions o;
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&](const char* name) -> std::string {
        if (i + 1 >= args.size()) throw InputError(fmt::format("stability: {} needs a value\n{}", name, kUsage));
        return args[++i];
      };
      if (a == "--out") out_dir = value("--out");
      else if (a == "--subset") {
        o.subset = value("--subset");
        if (o.subset != "quick" && o.subset != "all")
          throw InputError(fmt::format("stability: --subset '{}': expected quick or all", o.subset));
      } else if (a == "--cases") o.only = split_commas(value("--cases"));
      else if (a == "--binary") o.binary = value("--binary");
      else if (a == "--help" || a == "-h") {
        std::cout << kUsage;
        return 0;
      } else if (!a.empty() && a[0] == '-') throw InputError(fmt::format("stability: unknown option '{}'\n{}", a, kUsage));
      else if (suite_file.empty()) suite_file = a;
      else throw InputError(fmt::format("stability: more than one suite file ('{}', '{}')\n{}", suite_file.string(), a, kUsage));
    }
    if (suite_file.empty()) suite_file = default_suite();
    if (!fs::exists(suite_file)) throw InputError(fmt::format("stability: suite file {} does not exist", suite_file.string()));
    suite_file = fs::absolute(suite_file);
    const StabilitySuite suite = load_stability_suite(suite_file);
    if (o.binary.empty()) o.binary = self_executable().string();
    if (out_dir.empty()) out_dir = suite_file.parent_path() / (suite_file.stem().string() + ".work");
    o.out_dir = fs::absolute(out_dir);
    const StabilityReport r = run_stability_suite(suite, o, std::cout);
    return r.unexpected() ? 1 : 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

}  // namespace stentsim::study
