#pragma once
// A vessel out of a coronary tree for the segmentation stage (issue 3): the
// segment between two named points, or the longest path from the inlet, and
// optionally a region of interest of given length around the stenosis.
#include <Eigen/Core>

#include <optional>
#include <vector>

#include "common/stenosis_site.hpp"
#include "segmentation_io/branch_extraction.hpp"

namespace stentsim::segmentation {

/// The surface point farthest from `from` along the surface's edges (Dijkstra
/// on the vertex graph of the connected piece nearest to `from`), moved
/// `inset` mm inward along the piece's vertex normal. Along-surface distance
/// stands in for path length through the tree: the far end of its longest
/// vessel from the inlet.
Eigen::Vector3d farthest_point_along_surface(const TriSurface& tree, const Eigen::Vector3d& from, double inset);

/// The taper-discounted stenosis site lives in common/ (shared with the
/// device placement).
using stentsim::TaperedStenosis;
using stentsim::stenosis_discounting_taper;

/// The part of a vessel segment within ±length/2 (along its centerline) of
/// the stenosis (stenosis_discounting_taper between a local radius from each
/// end), cut by planes normal to the centerline; the window is
/// shifted to stay a local radius inside the segment's ends. `s0`, `s1`
/// receive the kept abscissae, `site` (when given) the stenosis. InputError when the segment is shorter than
/// `length`.
TriSurface clip_region_of_interest(const TriSurface& lumen, const CenterlineResult& centerline, double length,
                                   double& s0, double& s1, TaperedStenosis* site = nullptr);

}  // namespace stentsim::segmentation
