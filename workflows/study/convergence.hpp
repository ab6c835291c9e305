#pragma once
// Convergence measures of a refinement series (issue 11): the order fitted to
// errors against a known reference, and, without one, Richardson
// extrapolation from the three finest solutions at a constant refinement
// ratio with the observed order and Roache's grid convergence index
// (Roache 1994, "Perspective: a method for uniform reporting of grid
// refinement studies", safety factor 1.25 for three grids).
#include <optional>
#include <string>
#include <vector>

namespace stentsim::study {

/// Least-squares slope of log(error) against log(h) over the points with
/// finite, positive error; empty with fewer than two such points.
std::optional<double> fitted_order(const std::vector<double>& h, const std::vector<double>& error);

/// Orders between consecutive refinements, ln(e_i/e_j)/ln(h_i/h_j), in the given order.
std::vector<double> pairwise_orders(const std::vector<double>& h, const std::vector<double>& error);

struct Richardson {
  bool ok = false;             ///< extrapolation done (asymptotic, constant ratio)
  std::string message;         ///< why not, or "asymptotic"
  double ratio = 0;            ///< h_medium / h_fine
  double observed_order = 0;   ///< p = ln((f3 - f2) / (f2 - f1)) / ln r
  double extrapolated = 0;     ///< f1 + (f1 - f2) / (r^p - 1)
  double gci_fine = 0;         ///< 1.25 |(f1 - f2) / f1| / (r^p - 1); NaN when the QoI tends to 0
  double gci_fine_absolute = 0;  ///< 1.25 |f1 - f2| / (r^p - 1), in the QoI's unit
  /// The extrapolated limit is at most kVanishingQoi of the largest of the
  /// three solutions: the QoI tends to 0 and a relative GCI (and relative
  /// errors) would divide by the discretisation error or round-off; only the
  /// absolute GCI is reported.
  bool tends_to_zero = false;
  bool asymptotic = false;     ///< p within 0.5..1.5 x the theoretical order
};

/// A value whose magnitude is at most this fraction of the largest magnitude
/// in its series counts as zero for relative measures (relative error, GCI):
/// dividing by it would report round-off or the approach to 0, not accuracy.
inline constexpr double kVanishingQoi = 1e-3;

/// From three solutions f at sizes h (any order; the three finest are used).
/// Requires a constant ratio >= 1.5 (within 1 %) and monotone convergence;
/// otherwise ok = false with the reason. Without a theoretical order nothing
/// is judged or extrapolated (ok = false, "not judged").
Richardson richardson(std::vector<double> h, std::vector<double> f, std::optional<double> theoretical_order);

}  // namespace stentsim::study
