#pragma once
// summary.yaml, the contract that studies, cohorts and reports read
// (DESIGN.md §6): qoi: {name: {value, unit}}, plus wall_time_s and peak_memory_mb.
#include <filesystem>
#include <map>
#include <string>
#include <variant>
#include <vector>

namespace stentsim {

struct Qoi {
  std::variant<double, std::vector<double>, std::string> value;
  std::string unit;  // "" for dimensionless
};

class Summary {
 public:
  void set(const std::string& name, double value, const std::string& unit = "");
  void set(const std::string& name, std::vector<double> value, const std::string& unit = "");
  void set_text(const std::string& name, const std::string& value);
  /// Wall time and peak memory of the run this summary describes. A summary
  /// written without it (a stand-alone tool: `stentsim fibers`, `mesh`, ...)
  /// reports this process's own lifetime and peak memory, so every run's
  /// summary.yaml carries both (issue 11, DESIGN.md §6).
  void set_run(double wall_time_s, double peak_memory_mb);
  /// Free-form facts about how the result was made (model decisions, counts).
  void note(const std::string& key, const std::string& value);
  /// Writes atomically.
  void write(const std::filesystem::path& file) const;
  /// Reads a summary written by write().
  static Summary read(const std::filesystem::path& file);

  const std::map<std::string, Qoi>& qois() const { return qoi_; }
  double wall_time_s() const { return wall_time_s_; }
  double peak_memory_mb() const { return peak_memory_mb_; }

 private:
  std::map<std::string, Qoi> qoi_;
  std::map<std::string, std::string> notes_;
  double wall_time_s_ = 0, peak_memory_mb_ = 0;
  bool run_set_ = false;
};

/// Peak resident memory of this process so far, in MB (from getrusage).
double peak_memory_mb_self();

/// Seconds since this process started (steady clock, taken at static initialisation).
double process_wall_time_s();

}  // namespace stentsim
