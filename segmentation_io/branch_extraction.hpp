#pragma once
// One vessel segment out of a coronary tree (issue 3): the user names two
// points; the centerline between them is found on the tree's interior Voronoi
// diagram, the tree is cut by planes normal to the centerline at both ends,
// and side branches are cut off where they leave the vessel.
#include <Eigen/Core>

#include "segmentation_io/centerline.hpp"
#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::segmentation {

/// The part of `s` on the side (x − point)·normal ≤ 0; triangles crossing the
/// plane are split, so the cut is planar (it becomes an open end).
TriSurface clip_by_plane(const TriSurface& s, const Eigen::Vector3d& point, const Eigen::Vector3d& normal);

/// The connected pieces of a surface (through shared edges), largest area first.
std::vector<TriSurface> connected_pieces(const TriSurface& s);

struct BranchOptions {
  double spacing = 0.1;             // mm, centerline resampling
  double side_branch_cut = 1.6;     // triangles farther than this × local radius from the centerline are cut
  double end_margin = 0.0;          // mm cut off at each end along the centerline (keeps cuts off caps)
};

struct BranchSegment {
  TriSurface lumen;            // open at the two planar cuts; side-branch openings capped by a fan
  CenterlineResult centerline; // of the extracted segment
  int side_branches_cut = 0;
  int piece = -1;              // index into connected_pieces(tree) of the tree it came from
};

/// Extracts the segment between `a` and `b` (mm) from a closed tree surface
/// (several disconnected trees allowed: the piece nearest to `a` is used;
/// `b` must lie in the same). Throws InputError naming the points when they
/// are not in one vessel tree.
BranchSegment extract_branch(const TriSurface& tree, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const BranchOptions& options = {});

}  // namespace stentsim::segmentation
