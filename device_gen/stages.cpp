#include "device_gen/stages.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/error.hpp"
#include "common/log.hpp"
#include "common/mesh_data.hpp"
#include "device_gen/balloon_mesh.hpp"
#include "device_gen/placement_file.hpp"
#include "device_gen/stent_mesh.hpp"
#include "device_gen/stent_model.hpp"

namespace stentsim::device_gen {
namespace {

/// The axis for a device of `length`: the placement's, or straight.
DeviceAxis device_axis(const std::optional<std::filesystem::path>& placement_yaml, double balloon_length, bool check_length,
                       Summary& summary) {
  if (!placement_yaml) {
    summary.note("device_axis", "straight along +z, centred at the origin (no placement)");
    return DeviceAxis::straight(balloon_length);
  }
  const Placement P = read_placement_yaml(*placement_yaml);
  if (check_length && std::abs(P.balloon_length - balloon_length) > 1e-9)
    throw InputError(fmt::format("{}: the placement was made for a {} mm balloon, the design asks for {} mm; run the "
                                 "placement again",
                                 placement_yaml->string(), P.balloon_length, balloon_length));
  summary.note("device_axis", fmt::format("balloon centerline of {}", placement_yaml->string()));
  return axis_from_placement(P);
}

}  // namespace

void run_placement_stage(const PlacementParams& params, const std::filesystem::path& centerline_vtp,
                         const std::optional<std::filesystem::path>& lumen_vtp, const BalloonDesign& balloon,
                         const StentDesign& stent, const std::filesystem::path& out_placement_yaml,
                         const std::filesystem::path& out_balloon_centerline_vtp, Summary& summary) {
  const Centerline cl = read_centerline(centerline_vtp);
  std::optional<MeshData> lumen;
  if (lumen_vtp) lumen = read_vtp(lumen_vtp->string());
  const Placement P = compute_placement(params, cl, lumen ? &*lumen : nullptr, balloon, stent);
  const DeviceAxis axis = axis_from_placement(P);
  MeshData polyline = axis_polyline(axis);
  polyline.field_text["placement"] = out_placement_yaml.filename().string();
  write_placement_yaml(P, out_placement_yaml);
  write_vtp(out_balloon_centerline_vtp.string(), polyline);

  summary.set("stenosis_abscissa", P.site_abscissa, "mm");
  summary.set("narrowest_lumen_diameter", 2.0 * P.site_radius, "mm");  // inscribed lumen diameter at the site
  summary.set("smoothed_lumen_diameter", 2.0 * P.site_smoothed_radius, "mm");  // over device.placement.radius_window
  summary.note("site_chosen_by", P.site_chosen_by);
  if (P.site_reference_radius > 0) {
    summary.set("reference_lumen_diameter", 2.0 * P.site_reference_radius, "mm");
    summary.set("stenosis_percent_diameter", P.percent_diameter_stenosis(), "%");
    summary.set("reference_taper", P.reference_taper);  // dr_ref/ds
    summary.note("stenosis_rule", "lumen diameter at the site against the stenosis rule's reference line "
                                  "(common/stenosis_site.hpp, as the centerline stage and the segmentation ROI)");
  }
  summary.set("balloon_proximal_abscissa", P.proximal_abscissa, "mm");
  summary.set("balloon_distal_abscissa", P.distal_abscissa, "mm");
  summary.set("placement_min_clearance", P.clearance_min, "mm");
  summary.set("placement_weight_iterations", P.weight_iterations);
  summary.set("spline_residual", std::vector<double>{P.fits[0].residual, P.fits[1].residual, P.fits[2].residual}, "mm^2");
  summary.set("spline_knots", std::vector<double>{static_cast<double>(P.fits[0].spline.knots.size()),
                                                  static_cast<double>(P.fits[1].spline.knots.size()),
                                                  static_cast<double>(P.fits[2].spline.knots.size())});
  summary.set("balloon_centerline_length", axis.curve_length(), "mm");
  summary.set("balloon_centerline_max_curvature", axis.max_curvature(), "1/mm");
  summary.set_text("placement_site_chosen_by", P.site_chosen_by);
  summary.set_text("placement_clearance_method", P.clearance_method);
  summary.note("spline", "FITPACK curfit semantics (Dierckx), scipy UnivariateSpline-compatible; see placement.yaml");
  for (int k = 0; k < 3; ++k)
    if (!P.fits[static_cast<std::size_t>(k)].condition_met())
      summary.note(fmt::format("spline_{}", "xyz"[k]), fitpack::describe_ier(P.fits[static_cast<std::size_t>(k)].ier));
}

void run_balloon_stage(const BalloonDesign& design, const std::optional<std::filesystem::path>& placement_yaml,
                       const std::filesystem::path& out_balloon_vtu, Summary& summary) {
  const DeviceAxis axis = device_axis(placement_yaml, design.length, true, summary);
  const MeshData mesh = build_balloon_mesh(design, axis);
  write_vtu(out_balloon_vtu.string(), mesh);
  const int around = design.around(), along = design.along();
  summary.set("balloon_elements", around * along);
  summary.set("balloon_elements_around", around);
  summary.set("balloon_elements_along", along);
  summary.set("balloon_nodes", static_cast<double>(mesh.points.size()));
  summary.set("balloon_dofs", 3.0 * static_cast<double>(mesh.points.size()));
  summary.set("balloon_length", design.length, "mm");
  summary.set("balloon_outer_diameter", design.outer_diameter, "mm");
  summary.set("balloon_wall_thickness", design.wall_thickness, "mm");
  log::info("balloon: {} x {} = {} hex8 elements", around, along, around * along);
}

void run_stent_stage(const StentDesign& design, const std::optional<std::filesystem::path>& placement_yaml,
                     const std::filesystem::path& out_stent_vtu, Summary& summary) {
  double balloon_length = design.length();
  std::optional<Placement> P;
  if (placement_yaml) {
    P = read_placement_yaml(*placement_yaml);
    balloon_length = P->balloon_length;
    if (std::abs(P->stent_length - design.length()) > 1e-9 ||
        std::abs(P->stent_envelope_diameter - design.envelope_diameter()) > 1e-9)
      throw InputError(fmt::format("{}: the placement checked a stent of {} mm with envelope {} mm, the design is {} mm with "
                                   "envelope {} mm; run the placement again",
                                   placement_yaml->string(), P->stent_length, P->stent_envelope_diameter, design.length(),
                                   design.envelope_diameter()));
  }
  const DeviceAxis axis = device_axis(placement_yaml, balloon_length, false, summary);
  const StentModel model = build_stent(design, axis);
  write_vtu(out_stent_vtu.string(), stent_to_mesh(model, design));
  double connector = 0;
  for (const auto& m : model.members)
    if (m.kind == StentModel::kConnector) connector = m.straight_length;
  summary.set("stent_rings", design.rings);
  summary.set("stent_length", design.length(), "mm");
  summary.set("stent_beam_elements", static_cast<double>(model.elements.size()));
  summary.set("stent_nodes", static_cast<double>(model.points.size()));
  summary.set("stent_nodal_dofs", model.nodal_dofs());
  summary.set("stent_joints", static_cast<double>(model.joints.size()));
  summary.set("stent_fixations", static_cast<double>(model.fixations.size()));
  summary.set("stent_crimped_diameter", design.crimped_diameter, "mm");
  summary.set("stent_strut_length", design.strut_length(), "mm");
  summary.set("stent_connector_length", connector, "mm");
  summary.set_text("stent_connector_shape", to_string(design.connector_shape));
  summary.note("stent_joints", "every strut and connector owns its end nodes; joints are node pairs (DESIGN.md §8)");
  log::info("stent: {} rings, {} beam elements, {} nodal DOFs", design.rings, model.elements.size(), model.nodal_dofs());
}

}  // namespace stentsim::device_gen
