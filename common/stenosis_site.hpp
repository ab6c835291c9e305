#pragma once
// The stenosis of a tapering vessel, shared by the segmentation region of
// interest (segmentation_io/tree_input) and the device placement
// (device_gen/placement) so both name the same site and percent stenosis.
#include <vector>

namespace stentsim {

/// Coronary lumens narrow distally, so the narrowest radius can be a healthy
/// distal end. A straight reference line r_ref(s) is fitted to the upper
/// envelope of the radius (least squares, repeated on the samples at or above
/// the previous line less 2 % of its mean, so the stenosis drops out of the
/// fit), and the site is where r(s) / r_ref(s) is smallest, between lo and hi.
struct TaperedStenosis {
  double abscissa = 0;          // mm
  double radius = 0;            // mm, lumen radius there
  double reference_radius = 0;  // mm, r_ref at the site
  double slope = 0;             // dr_ref/ds (negative: narrowing distally)
  double percent_diameter() const { return 100.0 * (1.0 - radius / reference_radius); }
};

/// Throws ComputeError with fewer than three samples in [lo, hi] or a
/// non-positive reference line there.
TaperedStenosis stenosis_discounting_taper(const std::vector<double>& abscissa, const std::vector<double>& radius,
                                           double lo, double hi);

}  // namespace stentsim
