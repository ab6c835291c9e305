#pragma once
// A single-number QoI of a stage's summary.yaml, for the workflow tests.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <variant>

#include "common/summary.hpp"

namespace stentsim::testing {

/// The value of QoI `name` in `summary`; throws (a failed test) when it is missing or not one number.
inline double summary_qoi(const std::filesystem::path& summary, const std::string& name) {
  const auto s = Summary::read(summary);
  const auto it = s.qois().find(name);
  if (it == s.qois().end()) throw std::runtime_error(summary.string() + ": no " + name);
  const double* v = std::get_if<double>(&it->second.value);
  if (!v) throw std::runtime_error(summary.string() + ": " + name + " is not a single number");
  return *v;
}

}  // namespace stentsim::testing
