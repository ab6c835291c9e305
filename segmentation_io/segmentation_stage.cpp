#include "segmentation_io/segmentation_stage.hpp"

#include <fmt/format.h>

#include "common/error.hpp"
#include "common/log.hpp"
#include "segmentation_io/simvascular_io.hpp"
#include "segmentation_io/surface_distance.hpp"

namespace stentsim::segmentation {

SurfaceInput parse_surface_input(ConfigMap& section) {
  SurfaceInput in;
  in.lumen = section.path("lumen");
  if (section.has("wall")) in.wall = section.path("wall");
  in.checks.units = section.choice("units", {"mm", "cm", "m", "um"}, std::string("mm"));
  in.checks.repair = section.boolean("repair", true);
  in.checks.expected_open_ends = section.integer("open_ends", 2, Range::between(0, 2));
  in.synthesis.wall_thickness = section.quantity("wall_thickness", units::kLength, 0.5, Range::positive());
  in.synthesis.remodeling = section.number("remodeling", 0.0, Range::between(0, 1));
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
  in.checks.repair = section.boolean("repair", true);
  in.synthesis.wall_thickness = section.quantity("wall_thickness", units::kLength, 0.5, Range::positive());
  in.synthesis.remodeling = section.number("remodeling", 0.0, Range::between(0, 1));
  section.finish();
  auto ext = [&](const std::filesystem::path& f, const char* e, const std::string& key) {
    if (f.extension() != e) section.fail(key, fmt::format("expected a SimVascular {} file, got `{}`", e, f.string()));
  };
  ext(in.path, ".pth", "path");
  ext(in.lumen, ".ctgr", "lumen");
  if (in.wall) ext(*in.wall, ".ctgr", "wall");
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
  }
  return files;
}

SegmentationInput parse_segmentation_input(ConfigMap& input) {
  int count = int(input.has("phantom")) + int(input.has("surface")) + int(input.has("simvascular"));
  if (count != 1) input.fail("", "expected exactly one of `phantom:`, `surface:` or `simvascular:`");
  SegmentationInput out;
  if (input.has("phantom")) {
    auto sec = input.map("phantom");
    out.source = parse_phantom(sec);
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
    summary.set_text("wall_source", "phantom");
    return;
  }
  // Lumen and optional wall as raw surfaces in the files' units, then the
  // same checks, repairs and wall synthesis for every kind of input.
  TriSurface lumen_raw, wall_raw;
  bool have_wall = false;
  std::string lumen_name, wall_name, kind;
  SurfaceCheckOptions checks;
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
  SurfaceReport lr;
  TriSurface lumen = check_and_repair(std::move(lumen_raw), checks, lumen_name, lr);
  report_to_summary("lumen", lr, summary);
  TriSurface wall;
  if (have_wall) {
    SurfaceReport wr;
    wall = check_and_repair(std::move(wall_raw), checks, wall_name, wr);
    report_to_summary("wall", wr, summary);
    // The wall must enclose the lumen: a sample of lumen points must lie inside it.
    auto wl = boundary_loops(wall);
    TriSurface closed = capped(wall, wl);
    // The lumen's own end rings lie in the cut planes, where the wall's caps
    // are too (inside/outside is ambiguous there): they are not sampled.
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
      throw InputError(fmt::format("{}: {} of {} sampled lumen points lie outside the wall surface {}; is the wall the "
                                   "outer surface of the same vessel, in the same units?",
                                   lumen_name, outside, sample.size(), wall_name));
    summary.set_text("wall_source", "file");
  } else {
    wall = synthesize_wall(lumen, synthesis);
    summary.set_text("wall_source", "synthesized from the lumen");
    summary.set("wall_thickness_healthy", synthesis.wall_thickness, "mm");
    summary.set("wall_remodeling", synthesis.remodeling);
  }
  write_vtp(out_lumen_vtp.string(), to_output(lumen, lumen_name));
  write_vtp(out_wall_vtp.string(), to_output(wall, have_wall ? wall_name : "synthesized"));
  summary.set_text("input", kind);
  summary.set("lumen_triangles", double(lumen.num_triangles()));
  summary.set("wall_triangles", double(wall.num_triangles()));
  summary.set("lumen_surface_area", surface_area(lumen), "mm^2");
}

}  // namespace stentsim::segmentation
