#pragma once
// Scalar Laplace problems on a volume mesh (hex8, tet4, tet10) for the
// harmonic lifting of the fiber field (paper Section 4.2, Nagler et al.
// 2013): -div grad u = 0 with Dirichlet values on node sets and zero flux on
// the rest of the boundary. Assembled with the solver's reference elements
// (solver/fem) into its GlobalSystem and solved with its linear solvers.
#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <string>

#include "common/mesh_data.hpp"
#include "solver/linalg/linear_solver.hpp"

namespace stentsim::fibers {

struct LaplaceSolve {
  Eigen::VectorXd u;          // one value per mesh point (points of no volume cell keep 0)
  double relative_residual = 0;
  int iterations = 0;
  double seconds = 0;                                       // total
  double assembly_seconds = 0, setup_seconds = 0, solve_seconds = 0;  // phases (setup: matrix + preconditioner)
};

/// Solves the Laplace problem on the volume cells of `mesh` with u = value at
/// every node in `dirichlet` (node -> value). `solver` is a solver/linalg type
/// ("gmres_amg": scalar smoothed-aggregation AMG, the fast one on patient
/// meshes; "gmres_ilu", "direct", "eigen_lu"). Throws ComputeError when the linear
/// solver fails.
LaplaceSolve solve_laplace(const MeshData& mesh, const std::map<std::int64_t, double>& dirichlet,
                           solver::LinearSolverType solver);

/// Gradient of the nodal field `u` at the reference centroid of volume cell `c`.
Eigen::Vector3d centroid_gradient(const MeshData& mesh, std::size_t c, const Eigen::VectorXd& u);

/// Value of `u` at the reference centroid of volume cell `c`.
double centroid_value(const MeshData& mesh, std::size_t c, const Eigen::VectorXd& u);

/// True for the volume cell types the fiber stage handles (hex8, tet4, tet10).
bool is_volume_cell(CellType t);

}  // namespace stentsim::fibers
