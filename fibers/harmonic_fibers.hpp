#pragma once
// Fiber fields of a patient wall by harmonic lifting (paper Section 4.2,
// after Nagler et al. 2013; DESIGN.md §5):
//   t: Laplace, t = 0 on the endothelium, 1 on the outer wall -> radial = grad t / |grad t|
//   l: Laplace, l = 0 on the proximal cut, 1 on the distal cut (smooth axial direction)
//   longitudinal = the lumen-centerline tangent at the closest centerline point,
//     blended with grad l / |grad l| and projected onto the plane normal to radial
//   circumferential = longitudinal x radial (so (radial, circumferential, longitudinal) is right-handed)
//   Fiber1/2 = cos(phi) circumferential +/- sin(phi) longitudinal, phi per layer.
// Frames are evaluated at each volume cell's reference centroid; gradients of
// linear (tet4) fields are recovered to second order (harmonic_fibers.cpp).
#include <string>

#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "fibers/analytic_tube_fibers.hpp"
#include "solver/linalg/linear_solver.hpp"

namespace stentsim::fibers {

struct HarmonicFiberOptions {
  LayerAngles angles;                 // rad from circumferential, per tags::Layer
  /// Weight of the centerline tangent against grad l in the longitudinal
  /// direction (1: tangent only, 0: grad l only). Ours (the paper is silent).
  double centerline_weight = 0.5;
  /// solver/linalg type (gmres_ilu: ILU(1); gmres_amg: scalar SA-AMG; direct).
  /// On the quadratic transmural problem of the case2-rca tet10 wall (183,189
  /// nodes) ILU(1) set-up dominates: gmres_ilu 70 s CPU for both quadratic
  /// problems against 23 s with gmres_amg (bench_fibers).
  solver::LinearSolverType linear_solver = solver::LinearSolverType::gmres_amg;
  /// tet10 meshes: solve the longitudinal Laplace problem with linear
  /// elements on the tet10 corner nodes (the tet4 mesh of the same vertices;
  /// about 7x fewer unknowns) and interpolate linearly to the midside nodes;
  /// its gradient is recovered (polynomial-preserving recovery with the
  /// zero-flux condition on the wall faces). grad l only steers the
  /// longitudinal direction together with the centerline tangent, and l is
  /// the slow problem for the Krylov solvers (case2-rca tet10: 131 AMG
  /// iterations quadratic against 38 for t). false: quadratic as well.
  bool linear_on_corners = true;
  /// With linear_on_corners: the transmural problem on the corner nodes too
  /// (fastest; the radial direction then has the recovered tet4 accuracy,
  /// which misses issue 5's 0.5 deg mean on a tube with two tet10 through the
  /// wall: 0.565 deg). Default: t is solved on all 10 nodes (0.411 deg there).
  bool transmural_on_corners = false;
};

/// Figures of merit of a fiber field (recorded in summary.yaml).
struct FiberQuality {
  double orthonormality_error = 0;   // max |Q^T Q - I| over cells, Q = [radial circ long]
  double min_handedness = 0;         // min det Q (1 for a right-handed frame)
  double max_neighbour_fiber_angle_deg = 0;  // between face neighbours of the same layer (Fiber1, Fiber2)
  double max_neighbour_frame_angle_deg = 0;  // between face neighbours (radial, circ., long.)
  double transmural_min = 0, transmural_max = 0;  // nodal t over volume nodes
  double longitudinal_min = 0, longitudinal_max = 0;
  double tangent_blend_angle_max_deg = 0;  // max angle between centerline tangent and grad l (projected)
};

struct HarmonicFiberResult {
  MeshData fibers;  // volume cells only, frame and fiber cell arrays, t and l as point and cell arrays
  FiberQuality quality;
  double laplace_seconds = 0;
  double transmural_residual = 0, longitudinal_residual = 0;
  int transmural_iterations = 0, longitudinal_iterations = 0;
  std::size_t transmural_unknowns = 0, longitudinal_unknowns = 0;
};

/// `mesh`: volume cells with cell array Layer, boundary faces with FaceGroup
/// (endothelium, outer_wall, proximal_cut, distal_cut; common/mesh_tags.hpp).
/// `centerline`: a polyline (its first polyline/line cells, in order).
/// Throws InputError naming `source` for a missing array, face group, layer
/// angle or an empty centerline.
HarmonicFiberResult harmonic_fibers(const MeshData& mesh, const MeshData& centerline, const HarmonicFiberOptions& options,
                                    const std::string& source = "artery mesh");

/// Orthonormality, handedness and neighbour angles of a fiber field MeshData
/// (cell arrays Radial, Circumferential, Longitudinal, Fiber1, Fiber2, Layer).
FiberQuality fiber_quality(const MeshData& fibers);

/// Reads artery.vtu and centerline.vtp, writes fibers.vtu (atomic) and the QoIs to `summary`.
void write_harmonic_fibers(const std::string& artery_vtu, const std::string& centerline_vtp,
                           const HarmonicFiberOptions& options, const std::string& fibers_vtu, Summary& summary);

}  // namespace stentsim::fibers
