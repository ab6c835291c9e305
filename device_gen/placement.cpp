#include "device_gen/placement.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/log.hpp"
#include "common/mesh_tags.hpp"
#include "common/stenosis_site.hpp"
#include "common/units.hpp"
#include "device_gen/surface_distance.hpp"

namespace stentsim::device_gen {

PlacementParams parse_placement_params(ConfigMap& section) {
  PlacementParams p;
  if (section.has("site_abscissa"))
    p.site_abscissa = section.quantity("site_abscissa", units::kLength, std::nullopt, Range::any());
  p.smoothing = section.number("smoothing", p.smoothing, Range::positive());
  p.smoothing_tolerance = section.number("smoothing_tolerance", p.smoothing_tolerance, Range::between(1e-12, 0.5));
  p.spacing = section.quantity("spacing", units::kLength, p.spacing, Range::positive());
  p.radius_window = section.quantity("radius_window", units::kLength, p.radius_window, Range::non_negative());
  p.clearance_margin = section.quantity("clearance_margin", units::kLength, p.clearance_margin, Range::non_negative());
  p.weight_factor = section.number("weight_factor", p.weight_factor, Range{1.0, std::nullopt, false, true});
  p.weight_window = section.quantity("weight_window", units::kLength, p.weight_window, Range::non_negative());
  p.max_weight_iterations = section.integer("max_weight_iterations", p.max_weight_iterations, Range::between(0, 1000));
  section.finish();
  return p;
}

double Placement::envelope_radius(double at) const {
  const double mid = 0.5 * balloon_length;
  return std::abs(at - mid) <= 0.5 * stent_length + 1e-12 ? 0.5 * stent_envelope_diameter : 0.5 * balloon_outer_diameter;
}

Placement compute_placement(const PlacementParams& prm, const Centerline& cl, const MeshData* lumen,
                            const BalloonDesign& balloon, const StentDesign& stent) {
  Placement P;
  P.centerline_file = cl.source;
  P.balloon_length = balloon.length;
  P.balloon_outer_diameter = balloon.outer_diameter;
  P.stent_length = stent.length();
  P.stent_envelope_diameter = stent.envelope_diameter();
  P.smoothing = prm.smoothing;
  P.smoothing_tolerance = prm.smoothing_tolerance;
  P.clearance_margin = prm.clearance_margin;
  if (P.stent_length > P.balloon_length + 1e-12)
    throw InputError(fmt::format("placement: the stent ({:.4g} mm) is longer than the balloon ({:.4g} mm)", P.stent_length,
                                 P.balloon_length));
  const double L = balloon.length;

  // 1. The site: given; else the lesion a tree's region of interest was
  // centred on (lumen.vtp names it); else the most severe lesion by the
  // stenosis rule (common/stenosis_site, as the centerline stage and the
  // segmentation's region of interest). A vessel with no lesion needs a site.
  std::optional<StenosisProfile> prof;
  try {
    prof = analyse_stenoses(cl.abscissa, cl.radius, prm.stenosis);
  } catch (const ComputeError& e) {
    if (!prm.site_abscissa)
      throw InputError(fmt::format("placement: {} ({}); give the site with device.placement.site_abscissa", e.what(),
                                   cl.source));
  }
  if (prm.site_abscissa) {
    P.site_abscissa = *prm.site_abscissa;
    P.site_chosen_by = "given";
    if (P.site_abscissa < cl.begin() || P.site_abscissa > cl.end())
      throw InputError(fmt::format("placement: site_abscissa {} mm lies outside the centerline of {} ({} to {} mm)",
                                   P.site_abscissa, cl.source, cl.begin(), cl.end()));
  } else if (lumen && lumen->field_text.count(tags::kTreatedSite)) {
    // The segmentation centred its region of interest on a lesion (the tree's
    // roi_center or its most severe one): the lesion nearest that point.
    Eigen::Vector3d x;
    std::istringstream in(lumen->field_text.at(tags::kTreatedSite));
    in >> x.x() >> x.y() >> x.z();
    double at = cl.begin(), best = std::numeric_limits<double>::infinity();
    for (double sv : cl.abscissa) {
      const double d = (cl.point_at(sv) - x).norm();
      if (d < best) best = d, at = sv;
    }
    const Lesion* lesion = prof->nearest(at);
    P.site_abscissa = lesion && at >= lesion->start && at <= lesion->end ? lesion->abscissa : at;
    P.site_chosen_by = "the region of interest's lesion";
  } else {
    const Lesion* lesion = prof->most_severe();
    if (!lesion)
      throw InputError(fmt::format("placement: {} ({}); give the site with device.placement.site_abscissa (mm along "
                                   "the centerline) or lower stenosis.threshold_percent",
                                   prof->no_lesion_message(), cl.source));
    P.site_chosen_by = "most severe lesion";
    P.site_abscissa = lesion->abscissa;
  }
  P.site_point = cl.point_at(P.site_abscissa);
  P.site_radius = cl.radius_at(P.site_abscissa);
  P.site_smoothed_radius = cl.smoothed_radius(P.site_abscissa, prm.radius_window);
  // The reference (healthy) radius at the site from the rule's line, so the
  // percent stenosis is the lesion's.
  if (prof) {
    P.site_reference_radius = prof->reference_at(P.site_abscissa);
    P.reference_taper = prof->slope;
  }

  // 2. The balloon ends.
  P.proximal_abscissa = P.site_abscissa - 0.5 * L;
  P.distal_abscissa = P.site_abscissa + 0.5 * L;
  if (P.proximal_abscissa < cl.begin() - 1e-9)
    throw InputError(fmt::format(
        "placement: the balloon ({} mm) centred at the {} site (abscissa {:.4g} mm of {}) reaches {:.4g} mm beyond the "
        "proximal end of the centerline; the site must be at abscissa >= {:.4g} mm (device.placement.site_abscissa) or the "
        "balloon shorter",
        L, P.site_chosen_by, P.site_abscissa, cl.source, cl.begin() - P.proximal_abscissa, cl.begin() + 0.5 * L));
  if (P.distal_abscissa > cl.end() + 1e-9)
    throw InputError(fmt::format(
        "placement: the balloon ({} mm) centred at the {} site (abscissa {:.4g} mm of {}) reaches {:.4g} mm beyond the "
        "distal end of the centerline; the site must be at abscissa <= {:.4g} mm (device.placement.site_abscissa) or the "
        "balloon shorter",
        L, P.site_chosen_by, P.site_abscissa, cl.source, P.distal_abscissa - cl.end(), cl.end() - 0.5 * L));

  // 3. Resampling.
  const int m = std::max(8, static_cast<int>(std::lround(L / prm.spacing)));
  P.spacing_requested = prm.spacing;
  P.spacing = L / m;
  std::vector<Eigen::Vector3d> c(static_cast<std::size_t>(m) + 1);
  std::vector<double> r(c.size());
  for (int i = 0; i <= m; ++i) {
    const double xi = P.spacing * i;
    P.x.push_back(xi);
    c[static_cast<std::size_t>(i)] = cl.point_at(P.proximal_abscissa + xi);
    r[static_cast<std::size_t>(i)] = cl.radius_at(P.proximal_abscissa + xi);
    for (int k = 0; k < 3; ++k) P.y[static_cast<std::size_t>(k)].push_back(c[static_cast<std::size_t>(i)](k));
  }
  P.weights.assign(c.size(), 1.0);

  // 4. Clearance: distance to the endothelium (or the inscribed-sphere bound) minus the envelope radius.
  std::unique_ptr<SurfaceDistance> wall;
  if (lumen) {
    wall = std::make_unique<SurfaceDistance>(*lumen);
    std::vector<Eigen::Vector3d> inside(cl.points.begin(), cl.points.end());
    wall->calibrate_inside(inside);
    P.clearance_method = "lumen-surface";
  } else {
    P.clearance_method = "inscribed-sphere";
  }
  auto centre_at = [&](double xi) {
    const double t = std::clamp(xi / P.spacing, 0.0, static_cast<double>(m));
    const auto i = std::min(static_cast<std::size_t>(t), static_cast<std::size_t>(m) - 1);
    const double f = t - static_cast<double>(i);
    return std::pair<Eigen::Vector3d, double>{(1 - f) * c[i] + f * c[i + 1], (1 - f) * r[i] + f * r[i + 1]};
  };
  auto wall_distance = [&](double xi, const Eigen::Vector3d& p) {
    if (wall) return wall->signed_distance(p);
    const auto [centre, radius] = centre_at(xi);
    return radius - (p - centre).norm();
  };
  // The lumen itself must hold the device envelope along the centerline.
  {
    double worst = std::numeric_limits<double>::infinity();
    int at = -1;
    for (int i = 0; i <= m; ++i) {
      const double xi = P.x[static_cast<std::size_t>(i)];
      const double clr = wall_distance(xi, c[static_cast<std::size_t>(i)]) - P.envelope_radius(xi);
      if (clr < worst) {
        worst = clr;
        at = i;
      }
    }
    if (worst < prm.clearance_margin) {
      const double xi = P.x[static_cast<std::size_t>(at)];
      const Eigen::Vector3d p = c[static_cast<std::size_t>(at)];
      const bool on_stent = std::abs(xi - 0.5 * L) <= 0.5 * P.stent_length + 1e-12;
      throw InputError(fmt::format(
          "placement: the lumen of {} at abscissa {:.4g} mm (point {:.4g} {:.4g} {:.4g}) is narrower than the {} envelope: "
          "lumen radius {:.4g} mm by {}, device radius {:.4g} mm{}, overlap {:.4g} mm; {}",
          cl.source, P.proximal_abscissa + xi, p.x(), p.y(), p.z(), on_stent ? "crimped stent" : "balloon",
          wall_distance(xi, p), P.clearance_method, P.envelope_radius(xi),
          prm.clearance_margin > 0 ? fmt::format(" plus margin {:.4g} mm", prm.clearance_margin) : std::string(),
          prm.clearance_margin - worst,
          on_stent ? "choose a smaller crimped diameter (device.stent.crimped_diameter) or another site"
                   : "choose a smaller balloon (device.balloon.outer_diameter) or another site"));
    }
  }

  // 5. Fit, check, raise weights near violations, refit.
  std::vector<double> samples;
  for (int i = 0; i < m; ++i) {
    samples.push_back(P.x[static_cast<std::size_t>(i)]);
    samples.push_back(P.x[static_cast<std::size_t>(i)] + 0.5 * P.spacing);
  }
  samples.push_back(L);
  for (int iter = 0;; ++iter) {
    for (int k = 0; k < 3; ++k) {
      auto& fit = P.fits[static_cast<std::size_t>(k)];
      fit = fitpack::univariate_spline(P.x, P.y[static_cast<std::size_t>(k)], P.weights, prm.smoothing, 3,
                                       prm.smoothing_tolerance);
      if (fit.ier > 0)
        throw ComputeError(fmt::format("placement: the smoothing spline of coordinate {} failed: {} (FITPACK ier = {}); "
                                       "raise device.placement.smoothing",
                                       "xyz"[k], fitpack::describe_ier(fit.ier), fit.ier));
    }
    const SplineCurve curve = P.curve();
    P.clearance_min = std::numeric_limits<double>::infinity();
    std::vector<double> violations;
    for (double xi : samples) {
      const double clr = wall_distance(xi, curve.position(xi)) - P.envelope_radius(xi);
      if (clr < P.clearance_min) {
        P.clearance_min = clr;
        P.clearance_at = xi;
      }
      if (clr < prm.clearance_margin) violations.push_back(xi);
    }
    P.weight_iterations = iter;
    if (violations.empty()) break;
    if (iter >= prm.max_weight_iterations)
      throw InputError(fmt::format(
          "placement: after {} weight iterations the fitted balloon centerline still cuts the endothelium of {} at abscissa "
          "{:.4g} mm by {:.4g} mm; raise device.placement.max_weight_iterations or weight_factor, or lower smoothing",
          iter, cl.source, P.proximal_abscissa + P.clearance_at, prm.clearance_margin - P.clearance_min));
    for (std::size_t i = 0; i < P.x.size(); ++i)
      for (double v : violations)
        if (std::abs(P.x[i] - v) <= prm.weight_window + 1e-12) {
          P.weights[i] *= prm.weight_factor;
          break;
        }
  }
  // The frame's start: the centerline's parallel-transport normal at the proximal end.
  P.initial_normal = cl.normal_at(P.proximal_abscissa);
  log::info("placement: site at abscissa {:.4g} mm ({}), clearance {:.4g} mm after {} weight iteration(s)", P.site_abscissa,
            P.site_chosen_by, P.clearance_min, P.weight_iterations);
  return P;
}

}  // namespace stentsim::device_gen
