#include "segmentation_io/segmentation_stage.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "common/error.hpp"
#include "common/log.hpp"
#include "common/mesh_tags.hpp"
#include "segmentation_io/centerline.hpp"
#include "segmentation_io/label_image.hpp"
#include "segmentation_io/simvascular_io.hpp"
#include "segmentation_io/surface_distance.hpp"
#include "segmentation_io/tree_input.hpp"

namespace stentsim::segmentation {

/// A sample of the lumen's points (not its end rings, which lie in the cut
/// planes where the capped wall's caps are too) must lie inside the wall.
void check_wall_encloses_lumen(const TriSurface& lumen, const TriSurface& wall, const std::string& lumen_name,
                               const std::string& wall_what) {
  TriSurface closed = capped(wall, boundary_loops(wall));
  std::vector<char> on_end(lumen.points.size(), 0);
  for (const auto& loop : boundary_loops(lumen))
    for (int v : loop.vertices) on_end[std::size_t(v)] = 1;
  std::vector<Eigen::Vector3d> sample;
  std::size_t step = std::max<std::size_t>(1, lumen.points.size() / 500);
  for (std::size_t i = 0; i < lumen.points.size(); i += step)
    if (!on_end[i]) sample.push_back(lumen.points[i]);
  auto inside = inside_closed_surface(closed, sample);
  std::size_t outside = std::count(inside.begin(), inside.end(), false);
  // Points on the cut planes may sit on the wall's caps: allow a few.
  if (outside > sample.size() / 50)
    throw InputError(fmt::format("{}: {} of {} sampled lumen points lie outside {}", lumen_name, outside,
                                 sample.size(), wall_what));
}

double robust_reference_diameter(const StenosisProfile& p) { return 2 * p.reference_at(0.5 * (p.lo + p.hi)); }

WallSynthesisOptions parse_wall_synthesis(ConfigMap& section) {
  WallSynthesisOptions o;
  if (section.has("wall_thickness"))
    o.wall_thickness = section.quantity("wall_thickness", units::kLength, std::nullopt, Range::positive());
  o.nominal_intima = section.quantity("nominal_intima", units::kLength, o.nominal_intima, Range::positive());
  o.remodeling = section.number("remodeling", o.remodeling, Range::between(0, 1));
  return o;
}

SurfaceInput parse_surface_input(ConfigMap& section) {
  SurfaceInput in;
  in.lumen = section.path("lumen");
  if (section.has("wall")) in.wall = section.path("wall");
  in.checks.units = section.choice("units", {"mm", "cm", "m", "um"}, std::string("mm"));
  in.checks.units_key = section.key_path("units");
  in.checks.repair = section.boolean("repair", true);
  in.checks.expected_open_ends = section.integer("open_ends", 2, Range::between(0, 2));
  in.synthesis = parse_wall_synthesis(section);
  section.finish();
  if (in.checks.expected_open_ends != 2 && !in.wall)
    section.fail("open_ends", "a lumen for the pipeline needs its two open ends (proximal and distal cuts)");
  return in;
}

SimVascularInput parse_simvascular_input(ConfigMap& section) {
  SimVascularInput in;
  in.path = section.path("path");
  in.lumen = section.path("lumen");
  if (section.has("wall")) in.wall = section.path("wall");
  in.points_per_contour = section.integer("points_per_contour", 64, Range::between(8, 1024));
  in.checks.units = section.choice("units", {"mm", "cm", "m", "um"}, std::string("mm"));
  in.checks.units_key = section.key_path("units");
  in.checks.repair = section.boolean("repair", true);
  in.synthesis = parse_wall_synthesis(section);
  section.finish();
  auto ext = [&](const std::filesystem::path& f, const char* e, const std::string& key) {
    if (f.extension() != e) section.fail(key, fmt::format("expected a SimVascular {} file, got `{}`", e, f.string()));
  };
  ext(in.path, ".pth", "path");
  ext(in.lumen, ".ctgr", "lumen");
  if (in.wall) ext(*in.wall, ".ctgr", "wall");
  return in;
}

LabelImageInput parse_label_image_input(ConfigMap& section) {
  LabelImageInput in;
  in.file = section.path("file");
  in.lumen_label = section.integer("lumen_label", 1);
  if (section.has("wall_label")) in.wall_label = section.integer("wall_label");
  in.smoothing_iterations = section.integer("smoothing_iterations", 20, Range::between(0, 500));
  in.end_trim = section.quantity("end_trim", units::kLength, 0.0, Range::non_negative());
  in.units_given = section.has("units");
  in.checks.units = section.choice("units", {"mm", "cm", "m", "um"}, std::string("mm"));
  in.checks.units_key = section.key_path("units");
  in.checks.repair = section.boolean("repair", true);
  in.synthesis = parse_wall_synthesis(section);
  section.finish();
  if (in.wall_label && *in.wall_label == in.lumen_label)
    section.fail("wall_label", "must differ from lumen_label");
  std::string f = in.file.string();
  auto ends = [&](const std::string& e) { return f.size() >= e.size() && f.compare(f.size() - e.size(), e.size(), e) == 0; };
  if (!(ends(".nii") || ends(".nii.gz") || ends(".nrrd") || ends(".nhdr") || ends(".mha") || ends(".mhd")))
    section.fail("file", fmt::format("expected a NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr) or MetaImage (.mha, .mhd) "
                                     "label image, got `{}`", f));
  return in;
}

TreeInput parse_tree_input(ConfigMap& section) {
  TreeInput in;
  in.file = section.path("file");
  in.units = section.choice("units", {"mm", "cm", "m", "um"}, std::string("mm"));
  auto f = section.numbers("from", 3);
  in.from = {f[0], f[1], f[2]};
  const bool longest = section.boolean("longest_path_from_inlet", false);
  if (section.has("to")) {
    auto t = section.numbers("to", 3);
    in.to = Eigen::Vector3d(t[0], t[1], t[2]);
  }
  if (section.has("roi_length")) in.roi_length = section.quantity("roi_length", units::kLength, std::nullopt, Range::positive());
  if (section.has("roi_center")) {
    if (!in.roi_length) section.fail("roi_center", "needs roi_length (the region's length)");
    in.roi_center = section.quantity("roi_center", units::kLength, std::nullopt, Range::non_negative());
  }
  in.repair = section.boolean("repair", true);
  in.synthesis = parse_wall_synthesis(section);
  section.finish();
  if (longest == bool(in.to))
    section.fail(in.to ? "to" : "longest_path_from_inlet",
                 "expected exactly one of `to: [x, y, z]` or `longest_path_from_inlet: true`");
  return in;
}

TriSurface loft_simvascular(const std::filesystem::path& pth, const std::filesystem::path& ctgr,
                            int points_per_contour) {
  SvPath path = read_simvascular_path(pth);
  LoftOptions lo;
  lo.points_per_contour = points_per_contour;
  return loft_contours(path, read_simvascular_contours(ctgr), lo, ctgr.string());
}

std::vector<std::filesystem::path> SegmentationInput::input_files() const {
  std::vector<std::filesystem::path> files;
  if (const auto* in = std::get_if<SurfaceInput>(&source)) {
    files.push_back(in->lumen);
    if (in->wall) files.push_back(*in->wall);
  } else if (const auto* sv = std::get_if<SimVascularInput>(&source)) {
    files = {sv->path, sv->lumen};
    if (sv->wall) files.push_back(*sv->wall);
  } else if (const auto* li = std::get_if<LabelImageInput>(&source)) {
    files.push_back(li->file);
  } else if (const auto* tr = std::get_if<TreeInput>(&source)) {
    files.push_back(tr->file);
  }
  return files;
}

SegmentationInput parse_segmentation_input(ConfigMap& input) {
  int count = int(input.has("phantom")) + int(input.has("surface")) + int(input.has("simvascular")) +
              int(input.has("label_image")) + int(input.has("tree"));
  if (count != 1)
    input.fail("", "expected exactly one of `phantom:`, `surface:`, `simvascular:`, `label_image:` or `tree:`");
  SegmentationInput out;
  if (input.has("phantom")) {
    auto sec = input.map("phantom");
    out.source = parse_phantom(sec);
  } else if (input.has("tree")) {
    auto sec = input.map("tree");
    out.source = parse_tree_input(sec);
  } else if (input.has("label_image")) {
    auto sec = input.map("label_image");
    out.source = parse_label_image_input(sec);
  } else if (input.has("simvascular")) {
    auto sec = input.map("simvascular");
    out.source = parse_simvascular_input(sec);
  } else {
    auto sec = input.map("surface");
    out.source = parse_surface_input(sec);
  }
  input.finish();
  return out;
}

TriSurface load_checked_surface(const std::filesystem::path& file, const SurfaceCheckOptions& checks,
                                SurfaceReport& report) {
  TriSurface raw = read_surface_file(file);
  return check_and_repair(std::move(raw), checks, file.string(), report);
}

namespace {

/// `check` with the hint of load_stage_surface added to its InputError.
template <typename Check>
auto with_stage_hint(const std::string& tool, Check check) {
  try {
    return check();
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}\n{} takes surfaces in mm as `stentsim segmentation` writes them: run that on this "
                                 "file (a case file's input.surface.lumen or .wall, with its units) to check, scale and "
                                 "repair it", e.what(), tool));
  }
}

}  // namespace

TriSurface load_stage_surface(const std::filesystem::path& file, const std::string& tool) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  SurfaceCheckOptions checks;
  checks.repair = false;
  checks.repair_off_note = tool + " does not repair surfaces";
  checks.units_key = "input.surface.units";
  SurfaceReport report;
  return with_stage_hint(tool, [&] {
    if (ext != ".vtp")  // the stages read VTP only
      throw InputError(fmt::format("{}: {} reads VTP surfaces (.vtp), not {}", file.string(), tool,
                                   ext.empty() ? "a file without an extension" : ext));
    return load_checked_surface(file, checks, report);
  });
}

TriSurface load_stage_lumen(const std::filesystem::path& file, const std::string& tool) {
  TriSurface lumen = load_stage_surface(file, tool);
  with_stage_hint(tool, [&] {
    CenterlineOptions co;  // the default stenosis rule, as the segmentation stage's units rule without a case
    check_reference_diameter_units(robust_reference_diameter(compute_centerline(lumen, co).stenoses), "mm", file.string(),
                                   "input.surface.units");
  });
  return lumen;
}

void check_stage_wall(const TriSurface& lumen, const TriSurface& wall, const std::filesystem::path& lumen_file,
                      const std::filesystem::path& wall_file, const std::string& tool) {
  with_stage_hint(tool, [&] {
    check_wall_encloses_lumen(lumen, wall, lumen_file.string(),
                              "the wall " + wall_file.string() + "; is it the outer surface of the same vessel, in mm?");
  });
}

void report_to_summary(const std::string& prefix, const SurfaceReport& r, Summary& s) {
  s.set(prefix + "_merged_points", r.merged_points);
  s.set(prefix + "_degenerate_triangles_removed", r.degenerate_triangles);
  s.set(prefix + "_duplicate_triangles_removed", r.duplicate_triangles);
  s.set(prefix + "_pieces_dropped", r.pieces_dropped);
  s.set(prefix + "_orientation_flips", r.orientation_flips);
  s.set(prefix + "_normals_inverted", r.normals_inverted ? 1.0 : 0.0);
  s.set(prefix + "_holes_filled", r.holes_filled);
  s.set(prefix + "_open_ends", r.open_ends);
  for (std::size_t i = 0; i < r.notes.size(); ++i) s.note(fmt::format("{}_repair_{}", prefix, i + 1), r.notes[i]);
}

namespace {

MeshData to_output(const TriSurface& s, const std::string& source) {
  MeshData m = mesh_from_surface(s);
  m.field_text["units"] = "mm";
  m.field_text["source"] = source;
  return m;
}

}  // namespace

void run_segmentation_stage(const SegmentationInput& input, const std::filesystem::path& out_lumen_vtp,
                            const std::filesystem::path& out_wall_vtp, Summary& summary,
                            const std::filesystem::path& out_true_centerline) {
  if (input.is_phantom()) {
    const auto& spec = std::get<PhantomSpec>(input.source);
    std::filesystem::path cl = out_true_centerline;
    if (cl.empty()) cl = out_lumen_vtp.parent_path() / ".centerline_true.discarded.vtp";
    write_phantom(spec, out_lumen_vtp, out_wall_vtp, cl, summary);
    if (out_true_centerline.empty()) std::filesystem::remove(cl);
    summary.set_text("input", "phantom");
    summary.set_text("input_units", "mm");
    summary.set_text("wall_source", "phantom");
    return;
  }
  // Lumen and optional wall as raw surfaces in the files' units, then the
  // same checks, repairs and wall synthesis for every kind of input.
  TriSurface lumen_raw, wall_raw;
  std::optional<Eigen::Vector3d> roi_site;  // the lesion a tree's region of interest is centred on
  bool have_wall = false;
  std::string lumen_name, wall_name, kind;
  SurfaceCheckOptions checks;
  std::string input_units;  // the input files' length unit, for outputs in the input's units
  WallSynthesisOptions synthesis;
  if (const auto* sv = std::get_if<SimVascularInput>(&input.source)) {
    lumen_raw = loft_simvascular(sv->path, sv->lumen, sv->points_per_contour);
    lumen_name = sv->lumen.string();
    if (sv->wall) {
      wall_raw = loft_simvascular(sv->path, *sv->wall, sv->points_per_contour);
      wall_name = sv->wall->string();
      have_wall = true;
    }
    checks = sv->checks;
    synthesis = sv->synthesis;
    kind = "simvascular";
  } else if (const auto* li = std::get_if<LabelImageInput>(&input.source)) {
    // Units: the case's, else the NIfTI header's (xyzt_units), else mm; a
    // case that contradicts the header is an error.
    checks = li->checks;
    if (const auto header = nifti_spatial_units(li->file)) {
      if (!li->units_given) {
        checks.units = *header;
      } else if (*header != li->checks.units) {
        throw InputError(fmt::format("{}: the NIfTI header gives the voxel spacing in {} (xyzt_units), but "
                                     "input.label_image.units is {}; remove units or set it to {}",
                                     li->file.string(), unit_word(*header), li->checks.units, *header));
      }
      summary.note("label_image_units", fmt::format("{} ({})", checks.units,
                                                    li->units_given ? "input.label_image.units, as the NIfTI header"
                                                                    : "the NIfTI header's xyzt_units"));
    }
    LabelSurfaceOptions lo;
    lo.smoothing_iterations = li->smoothing_iterations;
    lo.end_trim = li->end_trim / unit_length_in_mm(checks.units);  // mm → the image's units
    lo.labels = {li->lumen_label};
    // Lumen and wall are cut by the same planes, placed by the outer region.
    if (li->wall_label) lo.axis_labels = {li->lumen_label, *li->wall_label};
    lumen_raw = label_image_surface(li->file, lo);
    lumen_name = li->file.string() + fmt::format(" (label {})", li->lumen_label);
    if (li->wall_label) {
      lo.labels = {li->lumen_label, *li->wall_label};
      wall_raw = label_image_surface(li->file, lo);
      wall_name = li->file.string() + fmt::format(" (labels {} and {})", li->lumen_label, *li->wall_label);
      have_wall = true;
    }
    synthesis = li->synthesis;
    kind = "label_image";
  } else if (const auto* tr = std::get_if<TreeInput>(&input.source)) {
    TriSurface tree = read_surface_file(tr->file);
    const double scale = unit_length_in_mm(tr->units);
    for (auto& x : tree.points) x *= scale;
    {  // Size says other units? (the same plausibility bounds as the surface checks)
      const SurfaceCheckOptions bounds;
      const double diag = bounding_box_diagonal(tree);
      if (diag < bounds.min_size || diag > bounds.max_size) {
        const std::string u = likely_units(diag, tr->units, bounds.min_size, bounds.max_size);
        throw InputError(fmt::format("{}: the tree is {:.4g} mm across with input.tree.units: {}; a coronary tree is {:g} "
                                     "to {:g} mm{}",
                                     tr->file.string(), diag, tr->units, bounds.min_size, bounds.max_size,
                                     u.empty() ? "" : fmt::format(" (the file looks like it is in {}: set input.tree.units: {})", unit_word(u), u)));
      }
    }
    Eigen::Vector3d to = tr->to ? *tr->to : farthest_point_along_surface(tree, tr->from, 0.3);
    BranchSegment seg = extract_branch(tree, tr->from, to);
    summary.set("tree_segment_length", seg.centerline.length, "mm");
    summary.set("tree_side_branches_cut", seg.side_branches_cut);
    if (!tr->to) summary.note("tree_path_end", fmt::format("longest path from the inlet ends at ({:.3f}, {:.3f}, {:.3f}) mm",
                                                           to.x(), to.y(), to.z()));
    lumen_raw = std::move(seg.lumen);
    // Units by the reference diameter of the whole extracted vessel (its
    // region of interest may sit on a small distal part).
    check_reference_diameter_units(robust_reference_diameter(seg.centerline.stenoses), tr->units,
                                   tr->file.string() + " (extracted segment)", "input.tree.units");
    if (tr->roi_length) {
      double s0 = 0, s1 = 0;
      TaperedStenosis site;
      StenosisProfile profile;
      lumen_raw = clip_region_of_interest(lumen_raw, seg.centerline, *tr->roi_length, input.stenosis, tr->roi_center, s0,
                                          s1, &site, &profile);
      summary.set("roi_start_abscissa", s0, "mm");
      summary.set("roi_end_abscissa", s1, "mm");
      summary.set("roi_stenosis_abscissa", site.abscissa, "mm");
      summary.set("roi_stenosis_percent_diameter", site.percent_diameter(), "%");
      summary.note("roi_centre", tr->roi_center ? "input.tree.roi_center" : "the most severe lesion of the segment");
      // The lesion the region was centred on, for the placement (whose
      // centerline's abscissae start again at the region's end).
      const auto& P = seg.centerline.centerline.points;
      const auto& S = seg.centerline.centerline.point_data.at("Abscissas").values;
      const std::size_t k = std::min<std::size_t>(
          P.size() - 1, std::size_t(std::lower_bound(S.begin(), S.end(), site.abscissa) - S.begin()));
      roi_site = P[k];
      summary.set("roi_site_point", std::vector<double>{P[k].x(), P[k].y(), P[k].z()}, "mm");
      report_lesions(profile, summary, "tree_");  // along the whole extracted segment
    }
    lumen_name = tr->file.string() + " (extracted segment)";
    input_units = tr->units;
    checks.units = "mm";  // already scaled
    checks.repair = tr->repair;
    synthesis = tr->synthesis;
    kind = "tree";
  } else {
    const auto& in = std::get<SurfaceInput>(input.source);
    lumen_raw = read_surface_file(in.lumen);
    lumen_name = in.lumen.string();
    if (in.wall) {
      wall_raw = read_surface_file(*in.wall);
      wall_name = in.wall->string();
      have_wall = true;
    }
    checks = in.checks;
    synthesis = in.synthesis;
    kind = "surface";
  }
  if (input_units.empty()) input_units = checks.units;
  SurfaceReport lr;
  TriSurface lumen = check_and_repair(std::move(lumen_raw), checks, lumen_name, lr);
  report_to_summary("lumen", lr, summary);
  // The lumen's centerline and lesions, for the units rule and the wall.
  CenterlineOptions co;
  co.stenosis = input.stenosis;
  const CenterlineResult lumen_centerline = compute_centerline(lumen, co);
  const double d_ref = robust_reference_diameter(lumen_centerline.stenoses);
  summary.set("lumen_reference_diameter", d_ref, "mm");
  if (kind != "tree")  // a tree's whole extracted segment was checked above
    check_reference_diameter_units(d_ref, checks.units, lumen_name, "input." + kind + ".units");
  TriSurface wall;
  if (have_wall) {
    SurfaceReport wr;
    wall = check_and_repair(std::move(wall_raw), checks, wall_name, wr);
    report_to_summary("wall", wr, summary);
    check_wall_encloses_lumen(lumen, wall, lumen_name,
                              "the wall surface " + wall_name + "; is the wall the outer surface of the same vessel, in the same units?");
    summary.set_text("wall_source", "file");
  } else {
    synthesis.stenosis = input.stenosis;
    synthesis.remedy = kind == "tree"        ? "move the region of interest (input.tree.roi_center, input.tree.roi_length)"
                       : kind == "surface"   ? "give the outer wall (input.surface.wall)"
                       : kind == "simvascular" ? "give the outer wall's contours (input.simvascular.wall)"
                                               : "label the wall in the image (input.label_image.wall_label)";
    wall = synthesize_wall(lumen, synthesis, summary, &lumen_centerline);
    {  // The checks a wall file gets, repairs off (as `stentsim mesh` gives wall.vtp).
      SurfaceCheckOptions wall_checks;
      wall_checks.repair = false;
      wall_checks.repair_off_note = "a synthesized wall is not repaired; " + synthesis.remedy;
      SurfaceReport wr;
      wall = check_and_repair(std::move(wall), wall_checks, "the wall synthesized from " + lumen_name, wr);
    }
    check_wall_encloses_lumen(lumen, wall, lumen_name, "the wall synthesized from it; " + synthesis.remedy);
    summary.set_text("wall_source", "synthesized from the lumen");
    summary.set("wall_remodeling", synthesis.remodeling);
  }
  MeshData lumen_out = to_output(lumen, lumen_name);
  if (roi_site) lumen_out.field_text[tags::kTreatedSite] = fmt::format("{:.17g} {:.17g} {:.17g}", roi_site->x(), roi_site->y(), roi_site->z());
  write_vtp(out_lumen_vtp.string(), lumen_out);
  write_vtp(out_wall_vtp.string(), to_output(wall, have_wall ? wall_name : "synthesized"));
  summary.set_text("input", kind);
  summary.set_text("input_units", input_units);
  summary.set("lumen_triangles", double(lumen.num_triangles()));
  summary.set("wall_triangles", double(wall.num_triangles()));
  summary.set("lumen_surface_area", surface_area(lumen), "mm^2");
}

}  // namespace stentsim::segmentation
