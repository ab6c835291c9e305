#pragma once
// The segmentation stage (DESIGN.md §1): from what the user brings — a
// phantom spec or segmented surfaces — to clean lumen.vtp and wall.vtp in mm.
#include <filesystem>
#include <optional>
#include <variant>

#include "common/config.hpp"
#include "common/stenosis_site.hpp"
#include "common/summary.hpp"
#include "segmentation_io/phantom.hpp"
#include "segmentation_io/surface_input.hpp"

namespace stentsim::segmentation {

struct CenterlineResult;  // segmentation_io/centerline.hpp

/// Outer wall made from the lumen alone (DESIGN.md §8). Per cross-section
/// normal to the lumen centerline: the lumen's polar contour (rays from the
/// centerline) is inflated to the healthy reference size r_ref(s) of the
/// stenosis rule where plaque narrows it (a healthy or oval lumen keeps its
/// shape), then dilated by the wall thickness t(s) as a distance level set in
/// the section plane (star-shaped about the centerline, never folding).
/// Rays that miss the lumen (open or oblique ends, ostia) are interpolated
/// from their neighbours. t(s) follows the layer rule
/// t = (t_I + 0.2146 D_ref)/0.5708 unless a fixed wall_thickness is given.
struct WallSynthesisOptions {
  std::optional<double> wall_thickness;  // mm, fixed; absent: the layer rule
  double nominal_intima = 0.1;           // mm, t_I of the layer rule
  double remodeling = 0.0;               // outward growth of the outer wall per mm of plaque (0: none, 1: full)
  int circumferential_points = 64;
  double station_spacing = 0.25;         // mm between the wall's sections
  double flare_ratio = 1.6;              // rays beyond this times r_ref are counted as flared (ostia, flared ends)
  StenosisRule stenosis;                 // the reference r_ref(s) (set from the case's `stenosis:` section)
  /// What the user can change when the wall cannot be built (set by the stage for its input kind).
  std::string remedy = "give the outer wall as a file";
};

/// Reads wall_thickness (length, optional), nominal_intima (length) and
/// remodeling of an input section (one parser for every input kind).
WallSynthesisOptions parse_wall_synthesis(ConfigMap& section);

/// The layer rule's wall thickness for a healthy reference lumen diameter.
double layer_rule_thickness(double reference_diameter, double nominal_intima);

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
  bool units_given = false;              // `units:` set in the case; else a NIfTI header's xyzt_units decides
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
  std::optional<double> roi_center;                // mm along the extracted segment; absent: the most severe lesion
  bool repair = true;
  WallSynthesisOptions synthesis;
};

/// Reads an `input.tree:` section: file, units, from ([x, y, z] in mm), to
/// ([x, y, z] in mm) or longest_path_from_inlet: true, roi_length (length,
/// optional), roi_center (length along the segment, optional), repair,
/// wall_thickness, nominal_intima, remodeling. Calls section.finish().
TreeInput parse_tree_input(ConfigMap& section);

/// What an `input:` section holds: exactly one of `phantom:`, `surface:`,
/// `simvascular:`, `label_image:` or `tree:`.
struct SegmentationInput {
  std::variant<PhantomSpec, SurfaceInput, SimVascularInput, LabelImageInput, TreeInput> source;
  StenosisRule stenosis;  // the case's `stenosis:` section (region of interest, wall synthesis)
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

/// A lumen or wall surface handed to a tool as a file (`stentsim mesh`, `stentsim
/// place`): read (VTP, as the stages read it) and given the surface checks in mm with
/// repairs off, which the segmentation stage's outputs pass. Its errors name the file
/// and say that `stentsim segmentation` (an input.surface section) scales and repairs
/// such a surface; `tool` is the command, for that message.
TriSurface load_stage_surface(const std::filesystem::path& file, const std::string& tool);
/// load_stage_surface for a lumen, with the case path's units rule too (its reference
/// diameter by its own centerline, the default stenosis rule).
TriSurface load_stage_lumen(const std::filesystem::path& file, const std::string& tool);
/// check_wall_encloses_lumen for the tools' files, with load_stage_surface's hint.
void check_stage_wall(const TriSurface& lumen, const TriSurface& wall, const std::filesystem::path& lumen_file,
                      const std::filesystem::path& wall_file, const std::string& tool);

/// InputError unless a sample of the lumen's points (its end rings aside) lies
/// inside the wall capped at its ends; `wall_what` says which wall, for the message.
void check_wall_encloses_lumen(const TriSurface& lumen, const TriSurface& wall, const std::string& lumen_name,
                               const std::string& wall_what);

/// The report's counts and repair notes as `<prefix>_...` QoIs and notes of `summary`.
void report_to_summary(const std::string& prefix, const SurfaceReport& report, Summary& summary);

/// The synthesized outer wall for a lumen (open tube, outward normals).
/// Summary: wall_thickness_min/max/reference, the fractions of missing and
/// flared rays, wall_min_clearance_ratio (smallest wall-to-lumen distance
/// over t, checked on planes between the sections). InputError when the wall
/// comes closer to the lumen than t/2 there.
/// `centerline`: the lumen's centerline when the caller has it (computed
/// with options.stenosis), else computed here.
TriSurface synthesize_wall(const TriSurface& lumen, const WallSynthesisOptions& options, Summary& summary,
                           const CenterlineResult* centerline = nullptr);

/// Twice the stenosis rule's reference radius at the middle of its analysed
/// range: the vessel's robust healthy diameter (the units rule's measure).
double robust_reference_diameter(const StenosisProfile& p);

}  // namespace stentsim::segmentation
