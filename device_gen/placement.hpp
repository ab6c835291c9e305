#pragma once
// Placement of the stenting device (paper 2.4; DESIGN.md §5 Placement, §8
// device sizing and reproducibility):
// 1. the stenosis site: the narrowest smoothed inscribed radius along the
//    centerline (ends excluded) relative to a straight reference line on the
//    radius's upper envelope (common/stenosis_site.hpp: discounts the vessel
//    taper, the same rule as the segmentation ROI), or a given abscissa;
// 2. the balloon ends at +- balloon length / 2 by arc length (an error says
//    by how much the balloon does not fit);
// 3. the centerline resampled at a fixed spacing between the ends; a cubic
//    smoothing spline per coordinate against the abscissa with FITPACK curfit
//    semantics (fitpack/curfit.hpp: |sum (w (y - s))^2 - zeta| < eps zeta);
// 4. the device envelope (crimped stent outer diameter over the stent, the
//    balloon outside it) checked against the lumen: where the lumen itself is
//    narrower, an error names the site and the overlap; otherwise weights are
//    raised near points where the fitted device would cut the endothelium and
//    the fit repeated until the clearance holds.
#include <Eigen/Core>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "common/mesh_data.hpp"
#include "common/stenosis_site.hpp"
#include "device_gen/balloon_design.hpp"
#include "device_gen/centerline_input.hpp"
#include "device_gen/fitpack/curfit.hpp"
#include "device_gen/spline_curve.hpp"
#include "device_gen/stent_design.hpp"

namespace stentsim {
class ConfigMap;
}

namespace stentsim::device_gen {

struct PlacementParams {
  std::optional<double> site_abscissa;  // mm along the centerline; default: the narrowest site
  double smoothing = 4.0;               // zeta (mm^2, per coordinate)
  double smoothing_tolerance = 0.001;   // epsilon (FITPACK tol)
  double spacing = 0.1;                 // mm, resampling of the centerline between the balloon ends
  double radius_window = 1.0;           // mm, moving average of the inscribed radius reported at the site
  /// The site by default: the most severe lesion of the stenosis rule
  /// (common/stenosis_site; the case's `stenosis:` section).
  StenosisRule stenosis;
  double clearance_margin = 0.0;        // mm the device envelope must stay inside the lumen
  double weight_factor = 2.0;           // weights near a violation are multiplied by this per iteration
  double weight_window = 0.5;           // mm around a violating sample whose weights are raised
  int max_weight_iterations = 40;
};

/// Reads a `device.placement` section: site_abscissa, smoothing,
/// smoothing_tolerance, spacing, radius_window,
/// clearance_margin, weight_factor, weight_window, max_weight_iterations.
/// Calls section.finish(). Throws InputError.
PlacementParams parse_placement_params(ConfigMap& section);

struct Placement {
  // Site and ends (centerline abscissae, mm).
  double site_abscissa = 0;
  std::string site_chosen_by;  // "most severe lesion" | "given"
  Eigen::Vector3d site_point = Eigen::Vector3d::Zero();
  double site_radius = 0, site_smoothed_radius = 0;
  // Taper reference line at the site (0 when fewer than three samples lie
  // between the excluded ends) and its slope dr_ref/ds.
  double site_reference_radius = 0, reference_taper = 0;
  double percent_diameter_stenosis() const {
    return site_reference_radius > 0 ? 100.0 * (1.0 - site_radius / site_reference_radius) : 0.0;
  }
  double proximal_abscissa = 0, distal_abscissa = 0;
  // Device used for the envelope.
  double balloon_length = 0, balloon_outer_diameter = 0, stent_length = 0, stent_envelope_diameter = 0;
  // The fit: x = abscissa - proximal_abscissa in [0, balloon_length].
  double spacing_requested = 0, spacing = 0;
  std::vector<double> x;
  std::array<std::vector<double>, 3> y;  // resampled centerline coordinates
  std::vector<double> weights;
  double smoothing = 0, smoothing_tolerance = 0;
  std::array<fitpack::SmoothingFit, 3> fits;
  int weight_iterations = 0;
  // Clearance of the device envelope from the lumen (mm, positive inside).
  std::string clearance_method;  // "lumen-surface" | "inscribed-sphere"
  double clearance_min = 0, clearance_at = 0, clearance_margin = 0;
  Eigen::Vector3d initial_normal = Eigen::Vector3d::UnitX();  // frame at the balloon's proximal end
  std::string centerline_file;

  SplineCurve curve() const { return {fits[0].spline, fits[1].spline, fits[2].spline}; }
  /// Envelope radius of the device at fit parameter x.
  double envelope_radius(double at) const;
};

/// Computes the placement. `lumen` (triangles) gives the clearance by the
/// distance to the endothelium; without it the inscribed sphere bounds it
/// (r(s) - |p(s) - c(s)|). Throws InputError when the device does not fit.
Placement compute_placement(const PlacementParams& params, const Centerline& centerline, const MeshData* lumen,
                            const BalloonDesign& balloon, const StentDesign& stent);

}  // namespace stentsim::device_gen
