#pragma once
// Synthetic patients (issue 3): an analytic coronary segment with a stenosis,
// written as lumen.vtp, wall.vtp and the exact lumen centerline with its true
// inscribed-sphere radius. They are the fixtures of most later tests.
//
// Geometry (phantom_geometry.cpp): the vessel axis c(s) is a straight line, a
// planar arc or a helix (optionally with a small seeded waviness). The lumen
// is the canal surface (envelope of spheres) of radius r(s) around the lumen
// spine γ(s) = c(s) − δ(s) n(s), where the plaque of eccentricity e pushes the
// lumen away from the plaque side n by δ = e (R0 − r). Because every sphere of
// a canal surface touches it along a circle, γ is exactly the medial axis and
// r exactly the maximum inscribed sphere radius: the true centerline is known
// in closed form, not approximately. The outer wall is a tube of circles
// normal to c with radius R0 + t(s) + remodeling·bump(s).
#include <filesystem>
#include <string>
#include <vector>

#include "common/config.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"

namespace stentsim::segmentation {

enum class PhantomCurve { straight, arc, helix };
const char* to_string(PhantomCurve c);

struct PhantomSpec {
  std::string preset = "custom";
  unsigned seed = 1;
  PhantomCurve curve = PhantomCurve::straight;
  double length = 20.0;                  // mm, along the vessel axis
  double radius_of_curvature = 10.0;     // mm (arc: the arc radius; helix: its constant curvature radius)
  double helix_pitch = 12.0;             // mm per turn (helix only)
  double waviness = 0.0;                 // mm, amplitude of a smooth seeded axis perturbation
  double reference_radius = 1.0;         // mm, healthy lumen radius R0
  double stenosis_severity = 0.0;        // % diameter reduction at the throat (0 = healthy)
  double stenosis_length = 8.0;          // mm, length of the cosine-shaped narrowing
  double stenosis_position = 0.5;        // fraction of the length where the throat sits
  double eccentricity = 0.0;             // 0 concentric .. <1 lumen pushed away from the plaque
  double plaque_angle = -1.0;            // rad, plaque side around the axis; < 0: drawn from the seed
  double wall_thickness_proximal = 0.5;  // mm, healthy wall at the proximal end
  double wall_thickness_distal = 0.5;    // mm, healthy wall at the distal end (linear in between)
  double remodeling = 0.0;               // mm, outward bump of the outer wall at the stenosis
  int circumferential_points = 64;       // points around each ring
  double axial_spacing = 0.0;            // mm between rings; 0: 2π R0 / circumferential_points
};

/// Presets: straight-healthy, case2-rca, severe-70, tortuous (DESIGN.md §8).
/// Throws InputError naming the preset and the choices when unknown.
PhantomSpec phantom_preset(const std::string& name, unsigned seed = 1);
const std::vector<std::string>& phantom_preset_names();

/// Reads a `phantom:` section: `preset` and `seed`, then any field of
/// PhantomSpec as an override (lengths with units). Calls section.finish().
PhantomSpec parse_phantom(ConfigMap& section);

/// Throws InputError naming the field when the spec is geometrically invalid
/// (wall or lumen through itself, stenosis outside the segment, ...).
void validate(const PhantomSpec& spec);

/// The three surfaces of a phantom, in mm.
struct PhantomGeometry {
  MeshData lumen;            // triangles, outward normals, open ends
  MeshData wall;             // outer wall surface, same conventions
  MeshData true_centerline;  // polyline γ with MaximumInscribedSphereRadius, Abscissas, ParallelTransportNormals
  double min_radius = 0;     // mm, true radius at the throat
  double stenosis_abscissa = 0;  // mm along the true centerline
  Eigen::Vector3d stenosis_point = Eigen::Vector3d::Zero();
  double wall_thickness_min = 0, wall_thickness_max = 0;  // mm, lumen to outer wall along the rings
};

/// Builds the phantom (deterministic for a given spec, including its seed).
PhantomGeometry build_phantom(const PhantomSpec& spec);

/// Writes lumen.vtp, wall.vtp and centerline_true.vtp to the given files and
/// the phantom's facts to `summary` (qoi: reference radius, throat radius,
/// stenosis abscissa, wall thickness range).
void write_phantom(const PhantomSpec& spec, const std::filesystem::path& lumen_vtp,
                   const std::filesystem::path& wall_vtp, const std::filesystem::path& centerline_true_vtp,
                   Summary& summary);
/// Same, into `out_dir` with the standard names (the folder is created).
void write_phantom(const PhantomSpec& spec, const std::filesystem::path& out_dir, Summary& summary);

}  // namespace stentsim::segmentation
