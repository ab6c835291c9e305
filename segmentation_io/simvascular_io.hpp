#pragma once
// SimVascular project input (issue 3): a path (`.pth`) and contour groups
// (`.ctgr`) for the lumen and optionally the outer wall, lofted into open
// tubes whose end rings are the proximal and distal cuts.
#include <Eigen/Core>

#include <filesystem>
#include <vector>

#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::segmentation {

/// One path of a `.pth` file (first timestep, first path element): the
/// densely sampled path points with their tangents.
struct SvPath {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> tangents;  // unit
};

/// One contour of a `.ctgr` file: a closed curve in a plane across the path.
struct SvContour {
  int id = -1;
  std::string type;                      // Circle, Ellipse, Polygon, SplinePolygon, ...
  Eigen::Vector3d path_position = Eigen::Vector3d::Zero();
  Eigen::Vector3d path_tangent = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> points;   // <contour_points>, in order around the curve
};

/// Reads `<path><timestep><path_element><path_points><path_point><pos/><tangent/>`.
/// InputError naming the file and the element for unparsable XML, a missing
/// element or attribute, a non-numeric coordinate or fewer than two points.
SvPath read_simvascular_path(const std::filesystem::path& file);

/// Reads `<contourgroup><timestep><contour>` with `<path_point>` and
/// `<contour_points>`; same errors, and a contour with fewer than three points.
std::vector<SvContour> read_simvascular_contours(const std::filesystem::path& file);

struct LoftOptions {
  int points_per_contour = 64;  // each contour resampled to this many points, equal arc length
  double axial_spacing = 0;     // mm between interpolated rings; 0: the circumferential spacing
};

/// The open tube through the contours: contours are ordered along the path
/// (by the abscissa of their centroid's nearest path point), resampled to
/// equal point counts, turned to run counter-clockwise about the path tangent,
/// their start points aligned (the rotation minimising the distance to the
/// previous ring), and joined by rings interpolated with Catmull-Rom splines
/// through corresponding points. Triangle normals point outward. InputError
/// (naming `what`) when fewer than two contours are given.
TriSurface loft_contours(const SvPath& path, std::vector<SvContour> contours, const LoftOptions& options,
                         const std::string& what);

}  // namespace stentsim::segmentation
