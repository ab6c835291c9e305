#pragma once
// The study file of `stentsim study error` (issue 11): a base input (a solver
// scene, or any input a stentsim command reads), the commands that turn it
// into a summary.yaml, the quantity of interest, its reference and the knobs
// to vary. Knobs name scene keys by dotted path (`bodies.0.mesh.generate.radial`);
// `@ranks` is the number of MPI ranks. Every key is validated; errors name the
// study file, the line and the key.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace stentsim::study {

/// One knob: one or more keys changed together, a list of settings.
struct Knob {
  std::string name;
  std::vector<std::string> keys;                 ///< dotted paths; "@ranks" = MPI ranks
  std::vector<std::vector<YAML::Node>> values;   ///< values[setting][key]
  std::vector<std::string> labels;               ///< one per setting
  std::vector<double> h;                         ///< mesh size per setting; empty: not a refinement knob
  /// Theoretical order of the error in h, for the "not asymptotic" check
  /// (observed order within 0.5..1.5x). `theoretical_order: 2`, or per line
  /// `theoretical_order: {default: 2, tet10-curved: 3}` whose other keys are
  /// setting labels of the study's other knobs (the grid line with that
  /// setting, or the base having it, is judged against that value).
  std::optional<double> theoretical_order;       ///< the default
  std::map<std::string, double> theoretical_order_by_setting;
  double cost_exponent = 0;                      ///< dry-run estimate: time ~ (h_ref / h)^exponent
};

struct Reference {
  enum class Type {
    tube_plane_strain,  ///< PlaneStrainTube shooting solution from each run's own scene
    beam_rollup,        ///< closed-form end-moment roll-up of a straight cantilever
    beam_plastic_rollup,///< the same with the App. C elasto-plastic moment-curvature closed form
    beam_shooting,      ///< rod equations under a dead tip force by shooting (the 45 deg bend)
    value,              ///< a given value (scalar or vector)
    qoi_is_error,       ///< the QoI is itself an error against a known truth (phantoms)
    richardson,         ///< extrapolated from the three finest settings of a knob
  };
  Type type = Type::value;
  std::vector<double> value;  ///< for `value`
  std::string knob;           ///< for `richardson`
};

struct StudyConfig {
  std::filesystem::path file;
  std::string name;
  std::filesystem::path base_file;  ///< the input every run starts from
  YAML::Node base;                  ///< its parsed content, with the study's `overrides` applied
  std::string base_name;            ///< file name the runs' input gets (base file's name)
  /// stentsim argument lists run in order; "{input}" is the run's input file, "{run}" its folder.
  std::vector<std::vector<std::string>> commands;
  std::string qoi;
  Reference reference;
  bool relative_error = true;
  double error_scale = 1;           ///< absolute errors are divided by this (e.g. the beam length)
  std::optional<double> tolerance;  ///< error tolerance for "the cheapest setting"
  std::vector<Knob> knobs;
  std::vector<std::string> grid;    ///< knobs varied as a full grid (besides one at a time)
  int base_ranks = 1;
  /// Recorded wall time of the base run (`base_time: 4 s`): the dry run's
  /// estimate before anything of the study was measured.
  std::optional<double> base_time_s;
};

/// The theoretical order along knob `along` for a line whose runs have the
/// other knobs at `setting` (knob name -> value index; absent: the base's
/// value, matched against the knob's settings). nullopt when none applies.
std::optional<double> theoretical_order_for(const StudyConfig& study, const Knob& along, const std::map<std::string, int>& setting);

/// Reads and validates a study file. Throws InputError naming file, line and key.
StudyConfig load_study(const std::filesystem::path& file);

/// Sets `dotted` (e.g. "bodies.0.mesh.generate.radial") in `root` to `value`.
/// Every intermediate key must exist; the last one may be new in a map.
/// Throws std::invalid_argument with the part of the path that is missing.
void set_dotted(YAML::Node root, const std::string& dotted, const YAML::Node& value);

/// The node at `dotted`, or an undefined node when absent.
YAML::Node get_dotted(const YAML::Node& root, const std::string& dotted);

}  // namespace stentsim::study
