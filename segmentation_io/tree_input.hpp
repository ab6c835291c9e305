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

/// The part of a vessel segment within ±length/2 (along its centerline) of a
/// lesion, cut by planes normal to the centerline: with `center` (an abscissa
/// of `centerline`) the lesion that spans it, or that abscissa itself; else
/// the most severe lesion by the stenosis rule (common/stenosis_site); with no lesion and no
/// center, an InputError that says so and names input.tree.roi_center. The
/// window is shifted to keep its cut planes a reference radius inside the
/// segment's ends. `s0`, `s1`
/// receive the kept abscissae, `profile` (when given) the rule's result and
/// `site` the lesion it is centred on. InputError when the segment is shorter
/// than `length`.
TriSurface clip_region_of_interest(const TriSurface& lumen, const CenterlineResult& centerline, double length,
                                   const StenosisRule& rule, std::optional<double> center, double& s0, double& s1,
                                   TaperedStenosis* site = nullptr, StenosisProfile* profile = nullptr);

}  // namespace stentsim::segmentation
