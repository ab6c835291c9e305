// The centerline stage: lumen.vtp -> centerline.vtp + summary QoIs.
#include <fmt/format.h>

#include "common/error.hpp"
#include "common/log.hpp"
#include "segmentation_io/centerline.hpp"

namespace stentsim::segmentation {

CenterlineOptions parse_centerline_options(ConfigMap& section) {
  CenterlineOptions o;
  o.spacing = section.quantity("spacing", units::kLength, 0.1, Range::between(kMinCenterlineSpacing, kMaxCenterlineSpacing));
  bool has_s = section.has("source"), has_t = section.has("target");
  if (has_s != has_t)
    section.fail(has_s ? "source" : "target", "give both source and target points (mm), or neither to use the open ends");
  if (has_s) {
    auto s = section.numbers("source", 3), t = section.numbers("target", 3);
    o.source_point = Eigen::Vector3d(s[0], s[1], s[2]);
    o.target_point = Eigen::Vector3d(t[0], t[1], t[2]);
  }
  o.centering_passes = section.integer("centering_passes", 2, Range::between(0, 10));
  o.smoothing_length = section.quantity("smoothing_length", units::kLength, o.smoothing_length, Range::between(0, 50));
  o.smoothing_bound = section.number("smoothing_bound", o.smoothing_bound, Range::between(0, 1));
  if (section.has("reference_radius"))
    o.reference_radius = section.quantity("reference_radius", units::kLength, std::nullopt, Range::positive());
  if (section.has("true_centerline")) o.true_centerline = section.path("true_centerline");
  section.finish();
  return o;
}

void run_centerline_stage(const CenterlineOptions& options, const std::filesystem::path& lumen_vtp,
                          const std::filesystem::path& out_centerline_vtp, Summary& summary) {
  run_centerline_stage(options, read_vtp(lumen_vtp.string()), lumen_vtp.string(), out_centerline_vtp, summary);
}

void run_centerline_stage(const CenterlineOptions& options, const MeshData& lumen, const std::string& source,
                          const std::filesystem::path& out_centerline_vtp, Summary& summary,
                          const std::function<void(const CenterlineResult&)>& before_write) {
  CenterlineResult r;
  try {
    r = compute_centerline(lumen, options);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", source, e.what()));
  }
  if (before_write) before_write(r);
  write_vtp(out_centerline_vtp.string(), r.centerline);
  summary.set("centerline_length", r.length, "mm");
  summary.set("centerline_points", double(r.centerline.points.size()));
  summary.set("centerline_spacing", options.spacing, "mm");
  summary.set("min_radius", r.min_radius, "mm");
  summary.set("stenosis_abscissa", r.stenosis_abscissa, "mm");
  summary.set("stenosis_point", std::vector<double>{r.stenosis_point.x(), r.stenosis_point.y(), r.stenosis_point.z()}, "mm");
  summary.set("reference_radius", r.reference_radius, "mm");
  summary.set("stenosis_percent_diameter", r.stenosis_percent_diameter, "%");
  summary.set("reference_taper", r.reference_taper);  // dr_ref/ds
  summary.set("voronoi_nodes", double(r.voronoi_nodes));
  summary.set("centerline_smoothing_displacement_max", r.smoothing_displacement_max, "mm");
  summary.set("lumen_triangles", double(lumen.num_cells()));
  summary.set("centerline_time_s", r.seconds, "s");
  summary.note("reference_radius", options.reference_radius ? "given in the case"
                                                            : "straight line fitted to the inscribed radius's upper "
                                                              "envelope away from the ends, at the stenosis site");
  summary.note("stenosis_site", r.stenoses.lesions.empty()
                                    ? "no lesion: the narrowest point relative to the reference line"
                                    : "the most severe lesion (lesion_<k>_*: every lesion)");
  report_lesions(r.stenoses, summary);
  summary.note("centerline_method", r.centerline.field_text["centerline_method"]);
  log::info("centerline: {:.2f} mm, stenosis radius {:.4f} mm at {:.2f} mm ({:.1f} % diameter stenosis), {:.2f} s",
            r.length, r.min_radius, r.stenosis_abscissa, r.stenosis_percent_diameter, r.seconds);
  if (options.true_centerline) {
    MeshData truth = read_vtp(options.true_centerline->string());
    CenterlineAccuracy acc = compare_with_true_centerline(r.centerline, truth);
    summary.set("centerline_distance_max", acc.centerline_distance_max, "");
    summary.set("inscribed_radius_error_max", acc.inscribed_radius_error_max, "");
    if (acc.stenosis_site_error)
      summary.set("stenosis_site_error", *acc.stenosis_site_error, "mm");
    else  // absent, so a study on it fails the row instead of reading 0 as perfect
      summary.note("stenosis_site_error", "not applicable: the true centerline has no stenosis");
    summary.note("accuracy", "relative to the local true radius, more than 2 true radii from the ends");
  }
}

}  // namespace stentsim::segmentation
