#include "common/units.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace stentsim::units {
namespace {

const std::unordered_map<std::string, Unit>& unit_table() {
  static const std::unordered_map<std::string, Unit> table = {
      // length (project unit: mm)
      {"mm", {1.0, kLength}},
      {"m", {1e3, kLength}},
      {"cm", {10.0, kLength}},
      {"um", {1e-3, kLength}},
      {"µm", {1e-3, kLength}},
      // force (N)
      {"N", {1.0, kForce}},
      {"mN", {1e-3, kForce}},
      {"kN", {1e3, kForce}},
      // pressure (MPa = N/mm^2)
      {"MPa", {1.0, kPressure}},
      {"kPa", {1e-3, kPressure}},
      {"Pa", {1e-6, kPressure}},
      {"GPa", {1e3, kPressure}},
      {"atm", {kAtmInMPa, kPressure}},
      {"mmHg", {kMmHgInMPa, kPressure}},
      {"bar", {0.1, kPressure}},
      // time (s)
      {"s", {1.0, kTime}},
      {"ms", {1e-3, kTime}},
      {"min", {60.0, kTime}},
      // angle (rad)
      {"rad", {1.0, kAngle}},
      {"deg", {std::numbers::pi / 180.0, kAngle}},
      {"°", {std::numbers::pi / 180.0, kAngle}},
  };
  return table;
}

Dimension scaled(const Dimension& d, int k) {
  return {d.length * k, d.force * k, d.time * k, d.angle * k};
}
Dimension add(const Dimension& a, const Dimension& b) {
  return {a.length + b.length, a.force + b.force, a.time + b.time, a.angle + b.angle};
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

}  // namespace

std::string describe(const Dimension& d) {
  if (d == kLength) return "a length, e.g. '0.25 mm'";
  if (d == kPressure) return "a pressure, e.g. '1.01 MPa', '13 atm', '85 mmHg' (N/mm^2 for a line penalty)";
  if (d == kStiffnessPerArea) return "a stiffness per area, e.g. '1000 N/mm^3'";
  if (d == kForce) return "a force, e.g. '0.1 N'";
  if (d == kMoment) return "a moment, e.g. '0.08 N*mm'";
  if (d == kTime) return "a time, e.g. '1 s'";
  if (d == kAngle) return "an angle, e.g. '40 deg'";
  if (d == kDimensionless) return "a plain number";
  return "a quantity with units";
}

Unit parse_unit(std::string_view text) {
  text = trim(text);
  if (text.empty()) return {1.0, kDimensionless};
  Unit result;
  int sign = +1;  // +1 before the first '/', -1 after it
  std::size_t pos = 0;
  while (pos <= text.size()) {
    std::size_t next = text.find_first_of("*/", pos);
    std::string_view token = trim(text.substr(pos, next == std::string_view::npos ? std::string_view::npos : next - pos));
    if (token.empty()) throw std::invalid_argument("malformed unit '" + std::string(text) + "'");
    int power = 1;
    if (auto caret = token.find('^'); caret != std::string_view::npos) {
      auto exp = token.substr(caret + 1);
      auto [p, ec] = std::from_chars(exp.data(), exp.data() + exp.size(), power);
      if (ec != std::errc() || p != exp.data() + exp.size())
        throw std::invalid_argument("bad exponent in unit '" + std::string(text) + "'");
      token = token.substr(0, caret);
    } else if (!token.empty() && (token.back() == '2' || token.back() == '3') && token.size() > 1 &&
               std::isalpha(static_cast<unsigned char>(token[token.size() - 2]))) {
      power = token.back() - '0';  // "mm2", "mm3"
      token.remove_suffix(1);
    }
    auto it = unit_table().find(std::string(token));
    if (it == unit_table().end())
      throw std::invalid_argument("unknown unit '" + std::string(token) + "'");
    result.factor *= std::pow(it->second.factor, sign * power);
    result.dim = add(result.dim, scaled(it->second.dim, sign * power));
    if (next == std::string_view::npos) break;
    if (text[next] == '/') {
      if (sign < 0) throw std::invalid_argument("unit '" + std::string(text) + "' has more than one '/'");
      sign = -1;
    }
    pos = next + 1;
  }
  return result;
}

double parse_quantity(std::string_view text, const Dimension& expected) {
  text = trim(text);
  double value = 0.0;
  auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc())
    throw std::invalid_argument("'" + std::string(text) + "' is not a number with a unit");
  std::string_view unit_text = text.substr(static_cast<std::size_t>(p - text.data()));
  if (!std::isfinite(value)) throw std::invalid_argument("value is not finite");
  if (trim(unit_text).empty()) return value;  // bare number: project units
  Unit u = parse_unit(unit_text);
  if (!(u.dim == expected))
    throw std::invalid_argument("unit '" + std::string(trim(unit_text)) + "' does not fit " + describe(expected));
  return value * u.factor;
}

}  // namespace stentsim::units
