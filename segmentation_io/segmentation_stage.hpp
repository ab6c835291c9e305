#pragma once
// The segmentation stage (DESIGN.md §1): from what the user brings — a
// phantom spec or segmented surfaces — to clean lumen.vtp and wall.vtp in mm.
#include <filesystem>
#include <optional>
#include <variant>

#include "common/config.hpp"
#include "common/summary.hpp"
#include "segmentation_io/phantom.hpp"
#include "segmentation_io/surface_input.hpp"

namespace stentsim::segmentation {

/// Outer wall made from the lumen alone (issue 3): a tube of circles normal to
/// the lumen centerline with radius R_ref + t + remodeling·(R_ref − r)₊, never
/// closer than t/2 to the lumen; R_ref(s) is the healthy reference line of
/// common/stenosis_site (fitted to the radius's upper envelope: the segments
/// either side of the stenosis, taper kept), r the local inscribed radius, so
/// the plaque fills the space between.
struct WallSynthesisOptions {
  double wall_thickness = 0.5;  // mm, healthy wall
  double remodeling = 0.0;      // outward growth of the outer wall per mm of plaque (0: none, 1: full)
  int circumferential_points = 64;
};

struct SurfaceInput {
  std::filesystem::path lumen;
  std::optional<std::filesystem::path> wall;  // absent: synthesized
  SurfaceCheckOptions checks;                 // units, repair, open ends
  WallSynthesisOptions synthesis;
};

/// Reads an `input.surface:` section: lumen (path), wall (path, optional),
/// units (mm|cm|m|um), repair (bool), open_ends (int), wall_thickness
/// (length), remodeling (number). Calls section.finish().
SurfaceInput parse_surface_input(ConfigMap& section);

/// A SimVascular project: a path and contour groups lofted into surfaces.
struct SimVascularInput {
  std::filesystem::path path;                        // .pth
  std::filesystem::path lumen;                       // .ctgr of the lumen
  std::optional<std::filesystem::path> wall;         // .ctgr of the outer wall; absent: synthesized
  int points_per_contour = 64;
  SurfaceCheckOptions checks;                        // units, repair
  WallSynthesisOptions synthesis;
};

/// Reads an `input.simvascular:` section: path (.pth), lumen (.ctgr), wall
/// (.ctgr, optional), units, repair, points_per_contour, wall_thickness,
/// remodeling. Calls section.finish().
SimVascularInput parse_simvascular_input(ConfigMap& section);

/// The lofted lumen (and wall, when given) of a SimVascular project, in the
/// files' units (not yet checked).
TriSurface loft_simvascular(const std::filesystem::path& pth, const std::filesystem::path& ctgr,
                            int points_per_contour);

/// A label image: lumen label (and optional wall label) → surfaces.
struct LabelImageInput {
  std::filesystem::path file;            // .nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd
  int lumen_label = 1;
  std::optional<int> wall_label;         // the wall region's label; the outer wall encloses lumen ∪ wall
  int smoothing_iterations = 20;
  double end_trim = 0;                   // mm; 0: automatic (see LabelSurfaceOptions)
  SurfaceCheckOptions checks;
  WallSynthesisOptions synthesis;
};

/// Reads an `input.label_image:` section: file, lumen_label, wall_label,
/// smoothing_iterations, end_trim (length), units, repair, wall_thickness,
/// remodeling. Calls section.finish().
LabelImageInput parse_label_image_input(ConfigMap& section);

/// A coronary tree (closed surface): one vessel out of it.
struct TreeInput {
  std::filesystem::path file;
  std::string units = "mm";
  Eigen::Vector3d from = Eigen::Vector3d::Zero();  // mm, inlet (proximal point)
  std::optional<Eigen::Vector3d> to;               // mm; absent: longest path from the inlet
  std::optional<double> roi_length;                // mm around the stenosis; absent: the whole segment
  bool repair = true;
  WallSynthesisOptions synthesis;
};

/// Reads an `input.tree:` section: file, units, from ([x, y, z] in mm), to
/// ([x, y, z] in mm) or longest_path_from_inlet: true, roi_length (length,
/// optional), repair, wall_thickness, remodeling. Calls section.finish().
TreeInput parse_tree_input(ConfigMap& section);

/// What an `input:` section holds: exactly one of `phantom:`, `surface:`,
/// `simvascular:`, `label_image:` or `tree:`.
struct SegmentationInput {
  std::variant<PhantomSpec, SurfaceInput, SimVascularInput, LabelImageInput, TreeInput> source;
  bool is_phantom() const { return std::holds_alternative<PhantomSpec>(source); }
  /// The user's files the stage reads (external inputs: editing one makes the stage stale).
  std::vector<std::filesystem::path> input_files() const;
};
/// Reads the case's `input:` section (calls finish() on it and its child).
SegmentationInput parse_segmentation_input(ConfigMap& input);

/// Runs the stage. For a phantom, `out_true_centerline` (when not empty)
/// receives the exact centerline too. Summary QoIs: triangle counts, repair
/// counts, open ends, wall source; for phantoms those of write_phantom.
void run_segmentation_stage(const SegmentationInput& input, const std::filesystem::path& out_lumen_vtp,
                            const std::filesystem::path& out_wall_vtp, Summary& summary,
                            const std::filesystem::path& out_true_centerline = {});

/// Reads and checks one surface file (units scaled to mm).
TriSurface load_checked_surface(const std::filesystem::path& file, const SurfaceCheckOptions& checks,
                                SurfaceReport& report);

/// The synthesized outer wall for a lumen (open tube, outward normals).
TriSurface synthesize_wall(const TriSurface& lumen, const WallSynthesisOptions& options);

}  // namespace stentsim::segmentation
