// The stenosis rule (common/stenosis_site.hpp).
#include "common/stenosis_site.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/summary.hpp"
#include "common/units.hpp"

namespace stentsim {

StenosisRule parse_stenosis_rule(ConfigMap& m) {
  StenosisRule r;
  r.threshold_percent = m.number("threshold_percent", r.threshold_percent, Range{0.0, 100.0, false, false});
  r.recovery_fraction = m.number("recovery_fraction", r.recovery_fraction, Range{0.0, 1.0, true, false});
  r.merge_distance = m.quantity("merge_distance", units::kLength, r.merge_distance, Range::non_negative());
  r.end_exclusion_diameters = m.number("end_exclusion_diameters", r.end_exclusion_diameters, Range::between(0, 20));
  r.smoothing_window = m.quantity("smoothing_window", units::kLength, r.smoothing_window, Range::non_negative());
  r.reference_window = m.quantity("reference_window", units::kLength, r.reference_window, Range{0.0, 1e6, false, true});
  m.finish();
  return r;
}

namespace {

struct Line {
  double a = 0, b = 0;  // r = a + b s
};

/// Upper-envelope least-squares line over the samples `inner`.
Line envelope_line(const std::vector<double>& S, const std::vector<double>& R, const std::vector<std::size_t>& inner) {
  Line l;
  std::vector<std::size_t> use = inner;
  for (int pass = 0; pass < 8; ++pass) {
    double n = 0, ss = 0, sr = 0, sss = 0, ssr = 0;
    for (std::size_t i : use) n += 1, ss += S[i], sr += R[i], sss += S[i] * S[i], ssr += S[i] * R[i];
    const double det = n * sss - ss * ss;
    l.b = det > 1e-12 * n * sss ? (n * ssr - ss * sr) / det : 0.0;
    l.a = (sr - l.b * ss) / n;
    double mean = 0;
    for (std::size_t i : inner) mean += l.a + l.b * S[i];
    mean /= double(inner.size());
    std::vector<std::size_t> next;
    for (std::size_t i : inner)
      if (R[i] >= l.a + l.b * S[i] - 0.02 * mean) next.push_back(i);
    if (next.size() < 2 || next == use) break;
    use = next;
  }
  return l;
}

std::vector<std::size_t> samples_between(const std::vector<double>& S, std::size_t n, double lo, double hi) {
  std::vector<std::size_t> inner;
  for (std::size_t i = 0; i < n; ++i)
    if (S[i] >= lo && S[i] <= hi) inner.push_back(i);
  return inner;
}

/// Moving average over [s - w/2, s + w/2] (trapezoidal in s, so uneven samples weigh by length).
std::vector<double> smoothed(const std::vector<double>& S, const std::vector<double>& R, double w) {
  const std::size_t n = std::min(S.size(), R.size());
  std::vector<double> out(R.begin(), R.begin() + long(n));
  if (w <= 0 || n < 2) return out;
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0, len = 0;
    for (std::size_t j = i; j > 0 && S[i] - S[j - 1] <= 0.5 * w; --j) {
      const double h = S[j] - S[j - 1];
      sum += 0.5 * h * (R[j] + R[j - 1]), len += h;
    }
    for (std::size_t j = i; j + 1 < n && S[j + 1] - S[i] <= 0.5 * w; ++j) {
      const double h = S[j + 1] - S[j];
      sum += 0.5 * h * (R[j] + R[j + 1]), len += h;
    }
    if (len > 0) out[i] = sum / len;
  }
  return out;
}

}  // namespace

StenosisProfile analyse_stenoses(const std::vector<double>& S, const std::vector<double>& Rraw, const StenosisRule& rule) {
  const std::size_t n = std::min(S.size(), Rraw.size());
  if (n < 3) throw ComputeError("stenosis rule: fewer than three centerline samples");
  const std::vector<double> R = smoothed(S, Rraw, rule.smoothing_window);
  StenosisProfile p;
  p.rule = rule;
  // The ends' exclusion is in reference diameters, so it needs the line; the
  // line is fitted on the samples the exclusion leaves: two passes settle it
  // (the line moves little once the tips are out).
  p.lo = S.front(), p.hi = S[n - 1];
  Line l = envelope_line(S, R, samples_between(S, n, p.lo, p.hi));
  for (int pass = 0; pass < 2; ++pass) {
    const double lo = S.front() + 2 * rule.end_exclusion_diameters * std::max(0.0, l.a + l.b * S.front());
    const double hi = S[n - 1] - 2 * rule.end_exclusion_diameters * std::max(0.0, l.a + l.b * S[n - 1]);
    const auto inner = samples_between(S, n, lo, hi);
    if (inner.size() < 3) {
      // Shorter than its two excluded ends: every sample is looked at, and
      // the profile (and summary) says so.
      p.lo = S.front(), p.hi = S[n - 1], p.ends_excluded = false;
      l = envelope_line(S, R, samples_between(S, n, p.lo, p.hi));
      break;
    }
    p.lo = lo, p.hi = hi;
    l = envelope_line(S, R, inner);
  }
  p.intercept = l.a, p.slope = l.b;
  const auto inner = samples_between(S, n, p.lo, p.hi);
  // Local fits where the analysed range is longer than the window (each
  // point's line over the window about it, clipped to the range); outside
  // the range the nearest end's value.
  if (p.hi - p.lo > rule.reference_window) {
    for (std::size_t i : inner) {
      const double c = std::clamp(S[i], p.lo + 0.5 * rule.reference_window, p.hi - 0.5 * rule.reference_window);
      const auto window = samples_between(S, n, c - 0.5 * rule.reference_window, c + 0.5 * rule.reference_window);
      const Line w = window.size() >= 3 ? envelope_line(S, R, window) : l;
      p.ref_s.push_back(S[i]);
      p.ref_r.push_back(w.a + w.b * S[i]);
    }
  }
  std::vector<double> depth(n, 0.0);  // percent diameter stenosis of the smoothed radius
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i : inner) {
    const double ref = p.reference_at(S[i]);
    if (ref <= 0) throw ComputeError(fmt::format("stenosis rule: the fitted reference radius is not positive at s = {:.3g} mm", S[i]));
    depth[i] = 100 * (1 - R[i] / ref);
    if (Rraw[i] / ref < best) best = Rraw[i] / ref, p.narrowest = {S[i], Rraw[i], ref, l.b};
  }
  // Cores: runs deeper than the threshold; each widens to where the narrowing
  // has recovered (below recovery_fraction of the threshold) on both sides.
  // A core that runs into an excluded end without recovering is a tip taper
  // or a cut lesion, not a lesion the rule can measure.
  const double recovered = rule.recovery_fraction * rule.threshold_percent;
  const std::size_t first = inner.front(), last = inner.back();
  std::vector<Lesion> found;
  for (std::size_t i = first; i <= last; ++i) {
    if (depth[i] <= rule.threshold_percent) continue;
    std::size_t j = i;
    while (j + 1 <= last && depth[j + 1] > rule.threshold_percent) ++j;
    std::size_t a = i, b = j;
    while (a > first && depth[a] > recovered) --a;
    while (b < last && depth[b] > recovered) ++b;
    // And the lumen widens again on both sides: the radius at each end of
    // the extent rises above the extent's smallest by what the recovery
    // means against a flat reference, (1 - recovery_fraction) of the
    // threshold. A step down at a branch (the reference, fitted over a
    // window, sits high just beyond it) has no distal rise and is no lesion.
    double rmin = std::numeric_limits<double>::infinity(), ref_min = 0;
    for (std::size_t k = a; k <= b; ++k)
      if (R[k] < rmin) rmin = R[k], ref_min = p.reference_at(S[k]);
    const double rise = (1 - rule.recovery_fraction) * rule.threshold_percent / 100 * ref_min;
    const bool ok = depth[a] <= recovered && depth[b] <= recovered && R[a] - rmin >= rise && R[b] - rmin >= rise;
    if (ok) {
      Lesion les;
      les.start = S[a], les.end = S[b];
      les.slope = (p.reference_at(S[b]) - p.reference_at(S[a])) / std::max(1e-12, S[b] - S[a]);
      // Found on the smoothed radius, measured on the raw one: the narrowest
      // raw r / r_ref inside the extent.
      double worst = std::numeric_limits<double>::infinity();
      for (std::size_t k = a; k <= b; ++k) {
        const double ref = p.reference_at(S[k]);
        if (Rraw[k] / ref < worst) worst = Rraw[k] / ref, les.abscissa = S[k], les.radius = Rraw[k], les.reference_radius = ref;
      }
      // Overlapping extents (a shallow saddle between two cores) are one lesion.
      if (!found.empty() && les.start <= found.back().end) {
        Lesion& prev = found.back();
        prev.end = std::max(prev.end, les.end);
        if (les.percent_diameter() > prev.percent_diameter()) {
          const double s0 = prev.start, s1 = prev.end;
          prev = les, prev.start = s0, prev.end = s1;
        }
      } else {
        found.push_back(les);
      }
    }
    i = std::max(j, b);
  }
  // Narrowings closer than merge_distance are one lesion: the deeper one names it.
  for (const Lesion& les : found) {
    if (!p.lesions.empty() && les.abscissa - p.lesions.back().abscissa < rule.merge_distance) {
      Lesion& prev = p.lesions.back();
      const double s0 = prev.start;
      if (les.percent_diameter() > prev.percent_diameter()) prev = les;
      prev.start = s0, prev.end = les.end;
    } else {
      p.lesions.push_back(les);
    }
  }
  return p;
}

double StenosisProfile::reference_at(double s) const {
  if (ref_s.empty()) return intercept + slope * s;
  if (s <= ref_s.front()) return ref_r.front();
  if (s >= ref_s.back()) return ref_r.back();
  const std::size_t j = std::size_t(std::upper_bound(ref_s.begin(), ref_s.end(), s) - ref_s.begin());
  const double f = (s - ref_s[j - 1]) / std::max(1e-12, ref_s[j] - ref_s[j - 1]);
  return (1 - f) * ref_r[j - 1] + f * ref_r[j];
}

const Lesion* StenosisProfile::most_severe() const {
  const Lesion* best = nullptr;
  for (const Lesion& l : lesions)
    if (!best || l.percent_diameter() > best->percent_diameter()) best = &l;
  return best;
}

const Lesion* StenosisProfile::nearest(double s) const {
  const Lesion* best = nullptr;
  double bd = std::numeric_limits<double>::infinity();
  for (const Lesion& l : lesions) {
    const double d = (s >= l.start && s <= l.end) ? -1.0 : std::abs(s - l.abscissa);
    if (d < bd) bd = d, best = &l;
  }
  return best;
}

std::string StenosisProfile::no_lesion_message() const {
  return fmt::format("no lesion deeper than {:g} % diameter stenosis (stenosis.threshold_percent) with recovery on both "
                     "sides between s = {:.2f} and {:.2f} mm; the narrowest point, at s = {:.2f} mm, is {:.1f} % against "
                     "the reference",
                     rule.threshold_percent, lo, hi, narrowest.abscissa, narrowest.percent_diameter());
}

void report_lesions(const StenosisProfile& p, Summary& summary, const std::string& prefix) {
  summary.set(prefix + "lesion_count", double(p.lesions.size()));
  summary.set(prefix + "reference_radius_intercept", p.intercept, "mm");
  summary.set(prefix + "reference_taper", p.slope);  // dr_ref/ds
  summary.note(prefix + "lesion_rule",
               fmt::format("narrowing deeper than {:g} % diameter stenosis against a reference line fitted to the "
                           "radius's upper envelope over {:g} mm about each point (follows the taper), recovering below "
                           "{:g} % on both sides; "
                           "narrowest points closer than {:g} mm merged; ends excluded by {:g} reference diameter(s); "
                           "radius averaged over {:g} mm",
                           p.rule.threshold_percent, p.rule.reference_window,
                           p.rule.recovery_fraction * p.rule.threshold_percent,
                           p.rule.merge_distance, p.rule.end_exclusion_diameters, p.rule.smoothing_window));
  if (p.lesions.empty()) summary.note(prefix + "lesions", p.no_lesion_message());
  if (!p.ends_excluded)
    summary.note(prefix + "lesion_ends", fmt::format("the vessel ({:.3g} mm) is shorter than its two excluded ends "
                                                     "(stenosis.end_exclusion_diameters): every sample was looked at",
                                                     p.hi - p.lo));
  for (std::size_t k = 0; k < p.lesions.size(); ++k) {
    const Lesion& l = p.lesions[k];
    const std::string key = fmt::format("{}lesion_{}_", prefix, k + 1);
    summary.set(key + "abscissa", l.abscissa, "mm");
    if (l.point) summary.set(key + "point", std::vector<double>(l.point->begin(), l.point->end()), "mm");
    summary.set(key + "min_radius", l.radius, "mm");
    summary.set(key + "reference_radius", l.reference_radius, "mm");
    summary.set(key + "percent_diameter", l.percent_diameter(), "%");
    summary.set(key + "percent_area", l.percent_area(), "%");
    summary.set(key + "start", l.start, "mm");
    summary.set(key + "end", l.end, "mm");
  }
}

}  // namespace stentsim
