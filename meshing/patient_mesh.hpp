#pragma once
// The patient wall mesh (paper Sections 2.1, 4.2; DESIGN.md §1, §5): layer
// interfaces from the lumen, outer wall and centerline, lofted with OCC and
// meshed with gmsh as one conforming tet mesh (tet10 by default).
#include <Eigen/Core>

#include <filesystem>
#include <string>
#include <vector>

#include "common/mesh_data.hpp"
#include "common/summary.hpp"

namespace stentsim::meshing {

struct PatientMeshOptions {
  std::string element = "tet10";  // tet10 | tet4
  double size = 0.25;             // mm, target edge length (paper: mean 0.25 mm)
  /// Floor of the local size as a fraction of `size`. With
  /// min_elements_per_layer >= 2, a layer whose thickness / n is below it is
  /// an InputError naming both settings (never a silent clamp); with n = 1 it
  /// is a floor (one element through holds in any conforming mesh).
  double min_size_ratio = 0.5;
  int min_elements_per_layer = 1; // through each layer: local size <= thickness / n (honoured for n >= 2)
  // Holzapfel et al. 2005 ratios of layer thickness to the local outer
  // diameter (0.22 / 2.8 and 0.38 / 2.8); 0 omits the layer. The rest is intima.
  double media_ratio = 0.0786, adventitia_ratio = 0.136;
  bool intima = true;             // false: media reaches the lumen (paper Case 1 style)
  double min_intima = 0.05;       // mm (DESIGN.md §8); thinner walls shrink media and adventitia to keep it
  double station_spacing = 0.5;   // mm between lofted cross-sections
  int points_per_section = 32;    // rays per cross-section
  /// mm cut off each centerline end, at least; where the section there
  /// leaves an obliquely cut open end, that end's trim grows up to one
  /// reference diameter (WallSections::end_trim_proximal/distal).
  double end_trim = 0.2;
  /// Consecutive sections must not meet inside the wall: each section's outer
  /// contour lies at least this fraction of the spacing beyond the
  /// neighbouring section's plane (1 on a straight tube, 1 - r/R on the inner
  /// side of a bend of radius R; 0.1 allows r up to 0.9 R).
  double min_section_gap_ratio = 0.1;
  /// Corner scaled Jacobian bound (1: regular tet, 0: flat). 0.05: gmsh's
  /// meshes of the thin (0.05 mm) intima and of the media keep a few near-flat
  /// elements (phantoms at 0.25 mm: min 0.052 tortuous, 0.100-0.138 the
  /// others); valid, positive-Jacobian elements.
  double min_scaled_jacobian = 0.05;
  double max_aspect_ratio = 50.0;
  /// gmsh 3D algorithm: "delaunay" (reproducible: the same input gives the
  /// same nodes and elements, in one process or across processes) or "hxt".
  /// gmsh 4.8's HXT adapter orders its input nodes by memory address
  /// (std::set<MVertex*>; gmsh issue 2255, fixed in gmsh 4.12), so repeated
  /// runs on the same input differed (case2-rca tet10 at 0.25 mm: 118,614 vs
  /// 118,557 tets in one process).
  std::string algorithm_3d = "delaunay";
  /// The mesh stage refuses, before gmsh runs, a mesh whose estimated tet count
  /// (estimate_elements) is above this: a size far too small would mesh for hours.
  /// case2-rca at 0.25 mm is ~1.2e5; 1e6 tet10 is ~4.5 M DOFs, more than a 12 GiB solve holds.
  double max_elements = 1e6;
};

/// Radii of the lumen, the layer interfaces and the outer wall along rays of
/// the cross-sections normal to the centerline.
struct WallSections {
  std::vector<Eigen::Vector3d> origin, tangent, normal, binormal;  // per station
  std::vector<double> abscissa;
  /// radius[s][k][i]: station s, surface k (0 lumen ... last outer wall), ray i.
  std::vector<std::vector<std::vector<double>>> radius;
  std::vector<int> layers;  // layer between surface k and k+1 (tags::Layer)
  double clamped_fraction = 0;  // rays where media/adventitia shrank to keep min_intima
  double min_gap_ratio = 1;     // smallest gap between consecutive sections / spacing (check_wall_sections)
  double end_trim_proximal = 0, end_trim_distal = 0;  // mm, the trims used
  Eigen::Vector3d point(std::size_t s, std::size_t k, std::size_t i) const;
};

/// Throws InputError naming the field.
void validate(const PatientMeshOptions& o);

/// Cuts the surfaces with planes normal to the centerline. InputError when a
/// ray misses the lumen or the wall or the wall is inside the lumen.
WallSections wall_sections(const MeshData& lumen, const MeshData& wall, const MeshData& centerline,
                           const PatientMeshOptions& o);

/// Before lofting (also called by wall_sections and mesh_wall_sections):
/// InputError naming the section, its arc length and position when (1) an
/// interface contour's spline folds back or crosses the next one outward, or
/// (2) consecutive sections meet inside the wall (see min_section_gap_ratio).
/// Returns the smallest gap found (fraction of the spacing; 1 on a straight tube).
double check_wall_sections(const WallSections& w, double min_gap_ratio);

/// InputError naming the layer, its thickness and position and the settings
/// mesh.min_elements_per_layer and mesh.min_size_ratio when some layer's
/// thickness / min_elements_per_layer on a section ray is below
/// min_size_ratio * size (the two settings conflict; no silent clamp).
/// Called by mesh_wall_sections before gmsh runs.
void check_layer_sizing(const WallSections& w, const PatientMeshOptions& o);

/// Estimated tets of mesh_wall_sections's mesh, per layer (index: the Layer tag): each
/// layer's volume between consecutive sections, ray by ray, over the volume per tet at
/// the local size gmsh is given there (as mesh_wall_sections sizes it). Within 2x of
/// the count gmsh makes on the phantoms (test_meshing_patient).
std::vector<double> estimate_elements(const WallSections& w, const PatientMeshOptions& o);

/// InputError naming mesh.size, mesh.max_elements and the estimate when the estimated
/// count is above o.max_elements, or when the size is so large that a layer's floor
/// (min_size_ratio * size) exceeds the whole wall's thickness many times over (gmsh
/// crashes on such input). Called by run_patient_mesh before gmsh runs; returns the
/// estimated total.
double check_element_budget(const WallSections& w, const PatientMeshOptions& o);

struct MeshQuality {
  /// Minimum over the tets of the corner scaled Jacobian of the straight-sided
  /// tet and, for tet10, of the quadratic map's scaled Jacobian at its four
  /// corners and four quadrature points (curved or misplaced midside nodes).
  double min_scaled_jacobian = 1, max_aspect_ratio = 1;
  /// tet10: min det J of the quadratic map at the corners and quadrature
  /// points over det J of the straight-sided tet (1 with straight edges, <= 0 inverted).
  double min_jacobian_ratio = 1;
  double mean_edge_length = 0;  // mm, over the corner edges of all tets (each tet's six, shared edges counted per tet)
  Eigen::Vector3d worst_sj_position = Eigen::Vector3d::Zero();
  int worst_sj_layer = 0;
  std::size_t worst_sj_cell = 0;
  Eigen::Vector3d worst_ar_position = Eigen::Vector3d::Zero();  // centroid of the tet with the largest aspect ratio
  int worst_ar_layer = 0;
  std::size_t worst_ar_cell = 0;
  std::vector<std::size_t> elements_per_layer = std::vector<std::size_t>(4, 0);  // by Layer tag
};

/// Scaled Jacobian (1 for the regular tet; see MeshQuality) and aspect ratio
/// (longest edge / (2 sqrt 6 inradius), 1 for the regular tet) of the tets.
MeshQuality mesh_quality(const MeshData& m);

/// gmsh adapter: loft, fragment, mesh. Returns artery MeshData (tets + tagged
/// boundary faces, outward) and writes `msh` (gmsh 4.1, physical groups).
MeshData mesh_wall_sections(const WallSections& w, const PatientMeshOptions& o, const std::filesystem::path& msh);

/// 128-bit hash (32 hex digits) of the node coordinates (bitwise), cell
/// types, connectivity and the Layer / FaceGroup tags: equal for equal meshes.
std::string mesh_fingerprint(const MeshData& m);

/// The stage: reads the three files, writes artery.vtu and artery.msh, quality
/// into `summary`; ComputeError when the quality is below the bounds.
void run_patient_mesh(const std::filesystem::path& lumen_vtp, const std::filesystem::path& wall_vtp,
                      const std::filesystem::path& centerline_vtp, const PatientMeshOptions& o,
                      const std::filesystem::path& artery_vtu, const std::filesystem::path& artery_msh,
                      Summary& summary);

}  // namespace stentsim::meshing
