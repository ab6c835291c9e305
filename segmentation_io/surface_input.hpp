#pragma once
// Segmented surfaces as users bring them (issue 3): reading through VTK's
// readers, unit handling, and the checks and repairs that make them usable.
#include <filesystem>
#include <string>
#include <vector>

#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::segmentation {

/// Reads a surface from .vtp, legacy .vtk, .stl (ASCII or binary) or .obj;
/// polygons and strips are triangulated. Throws InputError naming the file
/// when it is missing, of another kind, or holds no triangles.
TriSurface read_surface_file(const std::filesystem::path& file);

/// Length of one file unit in mm for "mm", "cm", "m", "um"; InputError otherwise.
double unit_length_in_mm(const std::string& unit);

/// The one units rule: a length measured as `value_mm` with the file read in
/// `declared` units lies outside [lo_mm, hi_mm]. Returns the other units in
/// which the same file value would fall inside (e.g. "cm": ×10 fits and ×1
/// does not), or "" when none does.
std::string likely_units(double value_mm, const std::string& declared, double lo_mm, double hi_mm);

/// "millimetres", "centimetres", "metres", "micrometres" for mm, cm, m, um.
std::string unit_word(const std::string& unit);

/// The plausible healthy reference lumen diameter of a coronary artery, mm.
inline constexpr double kMinReferenceDiameter = 1.5, kMaxReferenceDiameter = 8.0;

/// InputError when the lumen's robust reference diameter (twice the stenosis
/// rule's reference radius at the middle of its analysed range; not the
/// minimal one: a 70 % lesion is below 1 mm) is outside 1.5–8 mm, naming `what` (the
/// file), the diameter, the declared units and, where one fits, the setting
/// `units_key` and its likely value.
void check_reference_diameter_units(double reference_diameter_mm, const std::string& declared, const std::string& what,
                                    const std::string& units_key);

struct SurfaceCheckOptions {
  std::string units = "mm";           // units of the file's coordinates
  std::string units_key = "units";    // the setting that gives them, for errors ("input.surface.units", "--units")
  bool repair = true;                  // false: every defect is an error
  std::string repair_off_note = "repair is off";  // said beside a defect repair would mend, when it is off
  int expected_open_ends = 2;          // open tube ends (proximal and distal cuts); 0 for a closed surface
  double merge_tolerance = 1e-6;       // duplicate points closer than this × bounding-box diagonal are merged
  double small_piece_fraction = 0.01;  // repair drops pieces with less than this fraction of the area
  double small_hole_fraction = 0.5;    // repair fills holes whose perimeter is below this × the smaller end's
  double min_size = 1.0, max_size = 500.0;  // mm, plausible bounding-box diagonal of a coronary segment or tree
  bool check_self_intersections = true;
};

/// What the checks found and repaired (each count is also a summary QoI).
struct SurfaceReport {
  int merged_points = 0;
  int degenerate_triangles = 0;
  int duplicate_triangles = 0;
  int pieces_dropped = 0;
  int orientation_flips = 0;   // triangles turned to agree with their neighbours
  bool normals_inverted = false;  // all turned outward
  int holes_filled = 0;
  int open_ends = 0;
  std::vector<std::string> notes;  // human-readable, one per repair
};

/// Checks and repairs `s` (coordinates in options.units; returned in mm).
/// Errors (InputError, message starting with `what`): unreadable units,
/// non-manifold edges, self-intersections, several large pieces, more open
/// boundaries than expected that are not small holes, fewer open ends than
/// expected, and — with repair off — any defect that repair would fix.
TriSurface check_and_repair(TriSurface s, const SurfaceCheckOptions& options, const std::string& what,
                            SurfaceReport& report);

}  // namespace stentsim::segmentation
