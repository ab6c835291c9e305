#pragma once
// The lumen centerline (DESIGN.md §1 "centerline" stage, issue 3).
//
// Method, after VMTK (Antiga et al. 2004, see medial_axis.hpp):
//  1. interior Voronoi diagram of the lumen vertices (Delaunay poles);
//  2. minimal path on it between the two open ends (or two given points)
//     with cost ∫ 1/R ds (Dijkstra on the Voronoi edges), so that the path
//     keeps to the middle of the vessel and passes stenoses on their axis;
//  3. resampling at a fixed spacing;
//  4. centring (our addition, documented): each point is moved within the
//     plane normal to the centerline to the maximum of the distance to the
//     lumen surface, i.e. onto the centre of the maximum inscribed sphere,
//     which removes the zig-zag of the Voronoi path; two passes;
//  5. point arrays with VMTK names: MaximumInscribedSphereRadius (distance
//     to the surface), Abscissas, ParallelTransportNormals, plus
//     CenterlineSectionArea (area of the lumen cut by the normal plane).
#include <Eigen/Core>

#include <filesystem>
#include <functional>
#include <optional>

#include "common/config.hpp"
#include "common/stenosis_site.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::segmentation {

/// Bounds of the resampling spacing (mm): below the lower one a long vessel's
/// centerline holds millions of points (memory and time for nothing); above the
/// upper one a coronary's lesion falls between two points.
inline constexpr double kMinCenterlineSpacing = 0.01;
inline constexpr double kMaxCenterlineSpacing = 2.0;

struct CenterlineOptions {
  double spacing = 0.1;  // mm between output points, within the bounds above
  /// When both are given, the centerline runs between the interior Voronoi
  /// nodes nearest to them (needed for closed surfaces and trees); otherwise
  /// between the centroids of the two open ends.
  std::optional<Eigen::Vector3d> source_point, target_point;
  int centering_passes = 2;
  /// Smoothing of the centred path (kinks at lesions and junctions): a
  /// non-shrinking filter damping wavelengths below about 4 times this length
  /// (mm; 0: off), each point kept within smoothing_bound × its inscribed
  /// radius of the path.
  double smoothing_length = 1.0;
  double smoothing_bound = 0.3;
  /// Healthy reference radius for the % diameter stenosis; default: the
  /// taper line of common/stenosis_site at the stenosis site.
  std::optional<double> reference_radius;
  /// The lesions and the reference line (common/stenosis_site; the case's
  /// `stenosis:` section, shared with the ROI, wall synthesis and placement).
  StenosisRule stenosis;
  /// A true centerline (phantom) to report accuracy against.
  std::optional<std::filesystem::path> true_centerline;
};

/// Reads a `centerline:` section: spacing (length), source/target (3 numbers,
/// mm, both or neither), centering_passes, smoothing_length (length),
/// smoothing_bound, reference_radius, true_centerline (path). Calls
/// section.finish().
CenterlineOptions parse_centerline_options(ConfigMap& section);

struct CenterlineResult {
  MeshData centerline;  // one polyline with the point arrays listed above
  double length = 0;                  // mm
  /// Lesions and reference line by the stenosis rule (common/stenosis_site).
  StenosisProfile stenoses;
  // The site below is the most severe lesion's, or the narrowest point
  // relative to the reference line when there is no lesion.
  double min_radius = 0;              // mm, lumen radius at the stenosis site
  double stenosis_abscissa = 0;       // mm, stenosis site along the centerline
  Eigen::Vector3d stenosis_point = Eigen::Vector3d::Zero();
  double reference_radius = 0;        // mm, r_ref at the site (or CenterlineOptions::reference_radius)
  double reference_taper = 0;         // dr_ref/ds of the fitted reference line
  double stenosis_percent_diameter = 0;  // 100 (1 − r_min / r_ref)
  std::size_t voronoi_nodes = 0;
  double smoothing_displacement_max = 0;  // mm, largest move of a point by the smoothing
  double seconds = 0;                 // wall time of compute_centerline
};

/// Computes the centerline of a lumen surface (triangles, outward normals).
/// Throws ComputeError when no path joins the ends, InputError when the ends
/// cannot be found (not two open ends and no points given).
CenterlineResult compute_centerline(const TriSurface& lumen, const CenterlineOptions& options);
CenterlineResult compute_centerline(const MeshData& lumen, const CenterlineOptions& options);

/// Area of the cut of `surface` by the plane (point, unit normal) along the
/// loop that encloses `point`; 0 when no loop encloses it.
double section_area(const TriSurface& surface, const Eigen::Vector3d& point, const Eigen::Vector3d& normal);

/// Accuracy of a computed centerline against the true one (phantoms):
/// positions and radii compared at the closest point of the true polyline,
/// more than `end_exclusion_radii` true radii away from the true ends.
struct CenterlineAccuracy {
  double centerline_distance_max = 0;      // max distance / local true radius
  double inscribed_radius_error_max = 0;   // max |R − R_true| / R_true
  /// mm, between the computed and the true narrowest points; absent when
  /// the true centerline has no stenosis (a healthy phantom has no site to
  /// find, and 0 there would read as a perfect result).
  std::optional<double> stenosis_site_error;
  std::size_t points_compared = 0;
};
CenterlineAccuracy compare_with_true_centerline(const MeshData& computed, const MeshData& truth,
                                                double end_exclusion_radii = 2.0);

/// The stage: reads lumen.vtp, writes centerline.vtp and the summary QoIs
/// (centerline_length, min_radius, stenosis_abscissa, reference_radius,
/// stenosis_percent_diameter, centerline_time_s; with a true centerline also
/// centerline_distance_max, inscribed_radius_error_max, stenosis_site_error).
void run_centerline_stage(const CenterlineOptions& options, const std::filesystem::path& lumen_vtp,
                          const std::filesystem::path& out_centerline_vtp, Summary& summary);
/// The same on a lumen already read (`source` names it in errors): the stand-alone
/// tool passes a user's file through the case path's reader and surface checks first.
/// `before_write` sees the result before anything is written (the stand-alone tool's
/// units rule); it throws to refuse it.
void run_centerline_stage(const CenterlineOptions& options, const MeshData& lumen, const std::string& source,
                          const std::filesystem::path& out_centerline_vtp, Summary& summary,
                          const std::function<void(const CenterlineResult&)>& before_write = {});

}  // namespace stentsim::segmentation
