#pragma once
// A vessel out of a coronary tree for the segmentation stage (issue 3): the
// segment between two named points, or the longest path from the inlet, and
// optionally a region of interest of given length around the stenosis.
#include <Eigen/Core>

#include <optional>
#include <vector>

#include "segmentation_io/branch_extraction.hpp"

namespace stentsim::segmentation {

/// The surface point farthest from `from` along the surface's edges (Dijkstra
/// on the vertex graph of the connected piece nearest to `from`), moved
/// `inset` mm inward along the piece's vertex normal. Along-surface distance
/// stands in for path length through the tree: the far end of its longest
/// vessel from the inlet.
Eigen::Vector3d farthest_point_along_surface(const TriSurface& tree, const Eigen::Vector3d& from, double inset);

/// The stenosis of a tapering vessel: coronary lumens narrow distally, so the
/// narrowest radius can be a healthy distal end. A straight reference line
/// r_ref(s) is fitted to the upper envelope of the radius (least squares,
/// repeated on the samples at or above the previous line less 2 % of its
/// mean, so the stenosis drops out of the fit), and the site is where
/// r(s) / r_ref(s) is smallest, between lo and hi.
struct TaperedStenosis {
  double abscissa = 0;          // mm
  double radius = 0;            // mm, lumen radius there
  double reference_radius = 0;  // mm, r_ref at the site
  double slope = 0;             // dr_ref/ds (negative: narrowing distally)
  double percent_diameter() const { return 100.0 * (1.0 - radius / reference_radius); }
};
TaperedStenosis stenosis_discounting_taper(const std::vector<double>& abscissa, const std::vector<double>& radius,
                                           double lo, double hi);

/// The part of a vessel segment within ±length/2 (along its centerline) of
/// the stenosis (stenosis_discounting_taper between a local radius from each
/// end), cut by planes normal to the centerline; the window is
/// shifted to stay a local radius inside the segment's ends. `s0`, `s1`
/// receive the kept abscissae, `site` (when given) the stenosis. InputError when the segment is shorter than
/// `length`.
TriSurface clip_region_of_interest(const TriSurface& lumen, const CenterlineResult& centerline, double length,
                                   double& s0, double& s1, TaperedStenosis* site = nullptr);

}  // namespace stentsim::segmentation
