// The stenosis site discounting the vessel taper (common/stenosis_site.hpp).
#include "common/stenosis_site.hpp"

#include <cmath>
#include <limits>

#include "common/error.hpp"

namespace stentsim {

TaperedStenosis stenosis_discounting_taper(const std::vector<double>& S, const std::vector<double>& R, double lo,
                                           double hi) {
  std::vector<std::size_t> inner;
  for (std::size_t i = 0; i < S.size() && i < R.size(); ++i)
    if (S[i] >= lo && S[i] <= hi) inner.push_back(i);
  if (inner.size() < 3) throw ComputeError("stenosis site: fewer than three centerline samples between the ends");
  // Upper-envelope line: refit on the samples not below the last line by more than 2 % of its mean.
  double a = 0, b = 0;  // r_ref(s) = a + b s
  std::vector<std::size_t> use = inner;
  for (int pass = 0; pass < 8; ++pass) {
    double n = 0, ss = 0, sr = 0, sss = 0, ssr = 0;
    for (std::size_t i : use) n += 1, ss += S[i], sr += R[i], sss += S[i] * S[i], ssr += S[i] * R[i];
    const double det = n * sss - ss * ss;
    b = det > 1e-12 * n * sss ? (n * ssr - ss * sr) / det : 0.0;
    a = (sr - b * ss) / n;
    double mean = 0;
    for (std::size_t i : inner) mean += a + b * S[i];
    mean /= double(inner.size());
    std::vector<std::size_t> next;
    for (std::size_t i : inner)
      if (R[i] >= a + b * S[i] - 0.02 * mean) next.push_back(i);
    if (next.size() < 2 || next == use) break;
    use = next;
  }
  TaperedStenosis t;
  t.slope = b;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i : inner) {
    const double ref = a + b * S[i];
    if (ref <= 0) continue;
    if (R[i] / ref < best) best = R[i] / ref, t.abscissa = S[i], t.radius = R[i], t.reference_radius = ref;
  }
  if (!std::isfinite(best)) throw ComputeError("stenosis site: the fitted reference radius is not positive");
  return t;
}

}  // namespace stentsim
