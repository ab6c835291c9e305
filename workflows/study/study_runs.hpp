#pragma once
// The runs of an error study: the base input, each knob varied one at a time
// (the others at the base), and the full grid of the `grid` knobs. Identical
// effective inputs are one run. A run's key is the content hash of its
// effective input, its commands and its rank count: re-running a study
// computes only the points whose key has no cached result.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "workflows/study/study_config.hpp"

namespace stentsim::study {

struct RunSpec {
  std::string key;                    ///< content hash (hex)
  std::map<std::string, int> setting; ///< knob name -> index of its value; absent: the base's value
  YAML::Node input;                   ///< effective input
  std::string input_text;             ///< as written to the run's folder
  int ranks = 1;
  std::string label;                  ///< "base" or "h=8, element=tet10"
};

/// A line of the plots: runs along one knob, the others fixed.
struct Line {
  std::string label;               ///< "h" (one at a time) or "h | element=tet10" (grid)
  std::string knob;                ///< the knob varied along the line
  std::vector<std::size_t> runs;   ///< indices into the run list, in the knob's value order
  std::vector<int> settings;       ///< the knob's value index per run
};

struct StudyPlan {
  std::vector<RunSpec> runs;
  std::vector<Line> lines;
};

/// Expands the study into runs and lines. Throws InputError when a knob's key
/// cannot be set (naming study file, knob and key).
StudyPlan plan_study(const StudyConfig& study);

/// The argument vectors of a run (placeholders substituted); `binary` is the
/// stentsim executable; with ranks > 1 each command runs under mpirun.
std::vector<std::vector<std::string>> run_commands(const StudyConfig& study, const RunSpec& run,
                                                   const std::filesystem::path& run_dir, const std::string& binary);

/// The knob a value belongs to, for the table ("" when absent).
std::string setting_label(const StudyConfig& study, const RunSpec& run, const std::string& knob);

/// h of a run for a refinement knob (nullopt when the run keeps the base's value
/// or the knob has no h).
std::optional<double> run_h(const StudyConfig& study, const RunSpec& run, const std::string& knob);

}  // namespace stentsim::study
