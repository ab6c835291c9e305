#pragma once
// Quantities with units, converted once at input to the project's units:
// mm, N, MPa (= N/mm^2), s, rad (DESIGN.md §4).
#include <string>
#include <string_view>

namespace stentsim::units {

/// Physical dimension as exponents of length, force, time and angle.
struct Dimension {
  int length = 0, force = 0, time = 0, angle = 0;
  friend bool operator==(const Dimension&, const Dimension&) = default;
};

inline constexpr Dimension kDimensionless{};
inline constexpr Dimension kLength{1, 0, 0, 0};
inline constexpr Dimension kForce{0, 1, 0, 0};
inline constexpr Dimension kTime{0, 0, 1, 0};
inline constexpr Dimension kAngle{0, 0, 0, 1};
inline constexpr Dimension kPressure{-2, 1, 0, 0};        // MPa = N/mm^2; also line penalty N/mm^2
inline constexpr Dimension kStiffnessPerArea{-3, 1, 0, 0};  // N/mm^3 (springs, surface penalty)
inline constexpr Dimension kMoment{1, 1, 0, 0};            // N*mm

/// Human name with examples, used in error messages ("a pressure, e.g. '1.01 MPa', '13 atm'").
std::string describe(const Dimension& d);

/// A parsed unit: multiply a value in this unit by `factor` to get project units.
struct Unit {
  double factor = 1.0;
  Dimension dim;
};

/// Parses a unit expression such as "mm", "atm", "N/mm^3", "N*mm", "kPa".
/// Throws std::invalid_argument with a short reason for an unknown unit.
Unit parse_unit(std::string_view text);

/// Parses "13 atm" / "0.25mm" / "1e-3 m" and converts to the project unit of
/// `expected`. A bare number is taken in project units. Throws
/// std::invalid_argument with a reason when the text is not a quantity of
/// that dimension.
double parse_quantity(std::string_view text, const Dimension& expected);

/// Exact conversion constants used across the project.
inline constexpr double kAtmInMPa = 0.101325;
inline constexpr double kMmHgInMPa = 133.322387415e-6;

}  // namespace stentsim::units
