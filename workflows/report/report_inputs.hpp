#pragma once
// The files the report reads, each checked as it is read so that a damaged
// input is an InputError naming the file (and line), not a wrong report:
// solve/history.csv, the stages' summary.yaml (with their notes, which
// Summary keeps but does not expose) and solve/results.pvd.
#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/summary.hpp"

namespace stentsim::workflows::report {

/// solve/history.csv: one row per converged step, columns by name.
struct History {
  std::filesystem::path file;
  std::vector<std::string> columns;  ///< header order
  std::map<std::string, std::vector<double>> values;
  std::size_t rows = 0;

  bool has(const std::string& column) const { return values.count(column) > 0; }
  /// The column's values; an empty vector for a column that is not there.
  const std::vector<double>& column(const std::string& name) const;
  /// Columns named `prefix`...`suffix`, in header order.
  std::vector<std::string> columns_like(const std::string& prefix, const std::string& suffix) const;
  /// Sum of a column's finite values (0 for a missing column).
  double sum(const std::string& column) const;
};

/// The columns the solver writes on every run; the others are optional.
const std::vector<std::string>& required_history_columns();

/// Reads history.csv. InputError naming the file (and the line) when it is
/// missing, has no header, lacks a required column, repeats a column, or a row
/// has the wrong number of cells or a cell that is not a number ("nan" and
/// "inf" are numbers: the solver writes them for a quantity it could not measure).
History read_history(const std::filesystem::path& file);

/// Reads a summary.yaml that must be there; InputError naming it (and what
/// writes it) when it is missing or damaged.
Summary read_summary(const std::filesystem::path& file, const std::string& written_by);

/// The summary's `notes` (a map of free text, or one text) in file order.
std::vector<std::pair<std::string, std::string>> read_summary_notes(const std::filesystem::path& file);

/// One DataSet of results.pvd.
struct PvdFrame {
  double time = 0;
  std::string part;  ///< the body's name
  std::string file;  ///< relative to the .pvd's folder
};

/// Reads the DataSets of a ParaView collection file; InputError naming the
/// file when a DataSet has no file or a timestep that is not a number.
std::vector<PvdFrame> read_pvd(const std::filesystem::path& file);

/// The pressure column of the inflation: `pressure_inflation` when present,
/// else the first `pressure_<condition>` column that is not pressure_diastolic.
std::optional<std::string> inflation_pressure_column(const History& h);

/// Rows [0, end) of the inflation phase: up to the last row of the plateau
/// where the pressure first reaches its maximum (the end of the load phase
/// "max", DESIGN.md §6). 0 when the pressure never rises above zero.
std::size_t inflation_end(const std::vector<double>& pressure);

}  // namespace stentsim::workflows::report
