#include "workflows/study/convergence.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace stentsim::study {

std::optional<double> fitted_order(const std::vector<double>& h, const std::vector<double>& error) {
  std::vector<double> x, y;
  for (std::size_t i = 0; i < h.size() && i < error.size(); ++i)
    if (h[i] > 0 && std::isfinite(error[i]) && error[i] > 0) {
      x.push_back(std::log(h[i]));
      y.push_back(std::log(error[i]));
    }
  if (x.size() < 2) return std::nullopt;
  const double n = static_cast<double>(x.size());
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n, my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  if (sxx <= 0) return std::nullopt;
  return sxy / sxx;
}

std::vector<double> pairwise_orders(const std::vector<double>& h, const std::vector<double>& error) {
  std::vector<double> out;
  for (std::size_t i = 0; i + 1 < h.size() && i + 1 < error.size(); ++i) {
    const double e0 = error[i], e1 = error[i + 1];
    if (h[i] > 0 && h[i + 1] > 0 && h[i] != h[i + 1] && e0 > 0 && e1 > 0 && std::isfinite(e0) && std::isfinite(e1))
      out.push_back(std::log(e0 / e1) / std::log(h[i] / h[i + 1]));
    else out.push_back(std::nan(""));
  }
  return out;
}

Richardson richardson(std::vector<double> h, std::vector<double> f, std::optional<double> theoretical_order) {
  Richardson r;
  if (h.size() != f.size() || h.size() < 3) {
    r.message = "needs three solutions";
    return r;
  }
  std::vector<std::size_t> idx(h.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](auto a, auto b) { return h[a] < h[b]; });
  const double h1 = h[idx[0]], h2 = h[idx[1]], h3 = h[idx[2]];
  const double f1 = f[idx[0]], f2 = f[idx[1]], f3 = f[idx[2]];
  if (!std::isfinite(f1) || !std::isfinite(f2) || !std::isfinite(f3)) {
    r.message = "a solution of the three finest is missing";
    return r;
  }
  const double r21 = h2 / h1, r32 = h3 / h2;
  r.ratio = r21;
  if (std::abs(r21 - r32) > 0.01 * r21) {
    r.message = fmt::format("refinement ratio not constant ({:.4g} and {:.4g})", r21, r32);
    return r;
  }
  if (r21 < 1.5) {
    r.message = fmt::format("refinement ratio {:.4g} < 1.5", r21);
    return r;
  }
  const double e21 = f2 - f1, e32 = f3 - f2;
  if (e21 == 0 || e32 == 0 || e32 / e21 <= 0) {
    r.message = "oscillatory or stagnant convergence (f3 - f2 and f2 - f1 differ in sign or vanish)";
    return r;
  }
  r.observed_order = std::log(e32 / e21) / std::log(r21);
  if (!theoretical_order) {
    // Never judged against the observed order itself (that always passes).
    r.message = fmt::format("not judged: no theoretical_order for this line (observed order {:.3g}); not extrapolated",
                            r.observed_order);
    return r;
  }
  const double p_th = *theoretical_order;
  r.asymptotic = r.observed_order > 0 && r.observed_order >= 0.5 * p_th && r.observed_order <= 1.5 * p_th;
  if (!r.asymptotic) {
    r.message = fmt::format("not asymptotic: observed order {:.3g} outside 0.5-1.5 x {:.3g}", r.observed_order, p_th);
    return r;
  }
  const double rp = std::pow(r21, r.observed_order);
  r.extrapolated = f1 + (f1 - f2) / (rp - 1);
  r.gci_fine_absolute = 1.25 * std::abs(f1 - f2) / (rp - 1);
  // Roache's GCI is relative to f1: meaningless when the QoI tends to 0 (the
  // extrapolated limit vanishes against the solutions; f1 itself is then
  // mostly discretisation error).
  r.tends_to_zero = std::abs(r.extrapolated) <= kVanishingQoi * std::max({std::abs(f1), std::abs(f2), std::abs(f3)});
  r.gci_fine = r.tends_to_zero ? std::nan("") : 1.25 * std::abs((f1 - f2) / f1) / (rp - 1);
  r.ok = true;
  r.message = r.tends_to_zero ? fmt::format("asymptotic; the QoI tends to 0 (finest {:.3g}, coarsest {:.3g}): relative GCI undefined, "
                                            "absolute GCI {:.3g}", f1, f3, r.gci_fine_absolute)
                              : "asymptotic";
  return r;
}

}  // namespace stentsim::study
