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
  double gci_fine = 0;         ///< 1.25 |(f1 - f2) / f1| / (r^p - 1)
  bool asymptotic = false;     ///< p within 0.5..1.5 x the theoretical order
};

/// From three solutions f at sizes h (any order; the three finest are used).
/// Requires a constant ratio >= 1.5 (within 1 %) and monotone convergence;
/// otherwise ok = false with the reason. Without a theoretical order nothing
/// is judged or extrapolated (ok = false, "not judged").
Richardson richardson(std::vector<double> h, std::vector<double> f, std::optional<double> theoretical_order);

}  // namespace stentsim::study
