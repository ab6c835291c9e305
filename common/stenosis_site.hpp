#pragma once
// The one stenosis rule of the pipeline: the centerline
// stage, the device placement, the segmentation's region of interest and the
// wall synthesis all find lesions with analyse_stenoses, so they name the same
// sites, reference radii and percent stenoses.
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace stentsim {

class ConfigMap;
class Summary;

/// Settings of the rule (case section `stenosis:`).
struct StenosisRule {
  /// A lesion narrows the lumen diameter by more than this against the
  /// healthy reference (percent diameter stenosis; the paper's Case 2 is 20 %).
  double threshold_percent = 15;
  /// ... and recovers on both sides to less than this fraction of the threshold.
  double recovery_fraction = 0.5;
  /// Narrowings whose narrowest points are closer than this are one lesion (mm).
  double merge_distance = 3.0;
  /// Each end is left out by this many reference diameters (not the end's own
  /// radius, which shrinks at a tapering tip).
  double end_exclusion_diameters = 1.0;
  /// Moving average of the radius over this length before the rule (mm): the
  /// inscribed radius of a triangulated real surface is noisy.
  double smoothing_window = 0.5;
  /// The reference line is fitted over this length about each point (mm):
  /// a coronary's taper is not straight over a whole tree path (it steps down
  /// at each branch), and a lesion shorter than half of it drops out of the fit.
  double reference_window = 20.0;
};

/// Reads a `stenosis:` section (threshold_percent, recovery_fraction,
/// merge_distance, end_exclusion_diameters, smoothing_window,
/// reference_window); calls finish().
StenosisRule parse_stenosis_rule(ConfigMap& section);

/// The narrowest point of a tapering vessel relative to its reference line.
struct TaperedStenosis {
  double abscissa = 0;          // mm
  double radius = 0;            // mm, lumen radius there
  double reference_radius = 0;  // mm, r_ref at the site
  double slope = 0;             // dr_ref/ds (negative: narrowing distally)
  double percent_diameter() const { return 100.0 * (1.0 - radius / reference_radius); }
  double percent_area() const { return 100.0 * (1.0 - (radius / reference_radius) * (radius / reference_radius)); }
};

/// One lesion: its narrowest point and where it starts and ends (the
/// abscissae where the narrowing has recovered).
struct Lesion : TaperedStenosis {
  double start = 0, end = 0;          // mm
  std::optional<std::array<double, 3>> point;  // mm, where the caller knows the curve
};

/// The healthy reference r_ref(s) and the lesions. Coronary lumens narrow
/// distally, so the narrowest radius can be a healthy distal end: r_ref is a
/// line fitted by least squares to the upper envelope of the radius
/// (repeated on the samples at or above the previous line less 2 % of its
/// mean, so lesions drop out of the fit) over reference_window about each
/// point, so it follows the taper; on a vessel no longer than the window it
/// is one straight line, intercept + slope s.
struct StenosisProfile {
  double intercept = 0, slope = 0;    // the line over the whole analysed range
  std::vector<double> ref_s, ref_r;   // r_ref at the samples (local fits); empty: the line
  double lo = 0, hi = 0;              // the analysed range (ends excluded), mm
  bool ends_excluded = true;          // false: shorter than its excluded ends, every sample analysed
  std::vector<Lesion> lesions;        // in order of abscissa
  TaperedStenosis narrowest;          // smallest r / r_ref in [lo, hi], a lesion or not
  StenosisRule rule;
  double reference_at(double s) const;
  /// The deepest lesion (largest percent diameter stenosis); nullptr when none.
  const Lesion* most_severe() const;
  /// The lesion whose extent holds s, else the one whose narrowest point is
  /// nearest to s; nullptr when there is none.
  const Lesion* nearest(double s) const;
  /// "no lesion deeper than 15 % diameter stenosis with recovery on both sides between s = ... and ... mm"
  std::string no_lesion_message() const;
};

/// The rule on samples of radius R at abscissae S (increasing). A vessel
/// shorter than its two excluded ends is analysed whole (ends_excluded
/// false). Throws ComputeError with fewer than three samples or a
/// non-positive reference line.
StenosisProfile analyse_stenoses(const std::vector<double>& S, const std::vector<double>& R, const StenosisRule& rule = {});

/// Writes lesion_count and lesion_<k>_{abscissa, point, min_radius,
/// reference_radius, percent_diameter, percent_area, start, end} (k from 1,
/// by abscissa), the reference line and the rule into `summary`, with
/// `prefix` before every key (e.g. "roi_").
void report_lesions(const StenosisProfile& p, Summary& summary, const std::string& prefix = "");

}  // namespace stentsim
