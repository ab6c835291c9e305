#pragma once
// The linear-solver interface the nonlinear solver sees. Implementations:
// UMFPACK sparse LU ("direct", umfpack_solver.cpp; gathered on rank 0 on
// several ranks), Trilinos Belos GMRES with Ifpack2 ILU(k) or MueLu AMG
// (trilinos_solvers.cpp, the only C++17 file) and Eigen's SparseLU as a
// dependency-light reference.
#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

#include "solver/linalg/csr_matrix.hpp"

namespace stentsim::solver {

/// direct: UMFPACK sparse LU; gmres_ilu: Belos GMRES + Ifpack2 RILUK;
/// gmres_amg: Belos GMRES + MueLu SA-AMG (rigid-body near-null space);
/// eigen_lu: Eigen's SparseLU (single rank, a dependency-light reference);
/// gmres_amg_block: Belos GMRES + block Gauss-Seidel (block_split.hpp): MueLu
/// SA-AMG on one solid body's unknowns (set_amg_block), UMFPACK LU on the
/// rest (beams, a thin balloon: the unknowns AMG cannot aggregate). One rank.
/// gmres_lu: Belos GMRES preconditioned by a UMFPACK LU of the whole matrix,
/// kept for later matrices while that pays (lag_preconditioner): a Newton
/// iteration then costs a few triangular solves, not a factorization. One rank.
enum class LinearSolverType { direct, gmres_ilu, gmres_amg, eigen_lu, gmres_amg_block, gmres_lu };

/// True for the types that run on one MPI rank only (gmres_amg_block, gmres_lu, eigen_lu).
bool one_rank_only(LinearSolverType type);

/// The names every input accepts (scene, case, fibers stage, CLI), in enum order.
const std::vector<std::string>& linear_solver_names();
const std::string& linear_solver_name(LinearSolverType type);
/// Parses a name. An unknown one (an old spelling such as "gmres-amg" too)
/// throws InputError: "<where>: '<name>' is not one of: ... (did you mean ...)".
LinearSolverType parse_linear_solver(const std::string& name, const std::string& where);

struct LinearSolverSettings {
  LinearSolverType type = LinearSolverType::direct;
  double tolerance = 1e-10;   // relative residual of the Krylov solver
  int max_iterations = 2000;
  int krylov_size = 200;      // the paper's choice
  int ilu_fill = 4;           // the paper's choice
  /// gmres_amg: unknowns per mesh node (3 for displacements, 1 for a scalar
  /// field such as the fibers' Laplace problems). Without a near-null space
  /// MueLu then uses the constant per component.
  int amg_equations_per_node = 3;
  /// gmres_amg: a MueLu XML parameter list applied over ours (empty: none).
  std::string amg_parameters;
  /// Krylov solvers on one rank: keep the preconditioner of an earlier matrix
  /// (lagged) while the GMRES time it costs beyond a fresh one's rate has not
  /// yet paid for a new set-up; false: a new set-up for every matrix.
  bool lag_preconditioner = true;
  int verbosity = 0;
};

struct LinearSolveStats {
  int iterations = 0;        // 1 for direct solvers
  double relative_residual = 0.0;
  bool converged = false;
  double setup_seconds = 0.0, solve_seconds = 0.0;
  /// gmres_amg: levels of the MueLu hierarchy built for this solve (1 = the
  /// system was at or below the coarse size and was not coarsened); 0 otherwise.
  int amg_levels = 0;
  /// A preconditioner (AMG hierarchy, ILU factors) was built afresh for this solve, not kept.
  bool preconditioner_built = false;
  /// The preconditioner of an earlier matrix served this solve unchanged (lag_preconditioner).
  bool preconditioner_lagged = false;
  /// UMFPACK numeric factorizations made for this solve: 1 for direct and for a
  /// gmres_lu or gmres_amg_block set-up (the whole matrix, block 2), 0 when lagged.
  int lu_factorizations = 0;
};

class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  /// Solves A x = b. `a` holds this rank's contributions (summed over ranks
  /// by the solver); `b` is the full right-hand side (identical on all ranks);
  /// `x` receives the full solution on every rank.
  virtual LinearSolveStats solve(const CsrMatrix& a, const Eigen::VectorXd& b, Eigen::VectorXd& x) = 0;
  /// Near-null space for AMG (n x k, e.g. the 6 rigid-body modes); ignored by others.
  /// gmres_amg throws InputError at the next solve when its row count is not
  /// the system's, or when a row is zero in every mode (a DOF the modes do not
  /// describe, e.g. a beam rotation or a multiplier): SA-AMG with a fixed block
  /// of `amg_equations_per_node` would otherwise build a wrong coarse space.
  virtual void set_near_null_space(const Eigen::MatrixXd& modes) {}
  /// AMG: the mesh nodes' coordinates (row i: the node of unknowns eq*i .. eq*i+eq-1),
  /// for MueLu's geometric options (a distance-Laplacian drop); ignored by others.
  virtual void set_node_coordinates(const Eigen::MatrixXd& xyz) {}
  /// gmres_amg_block: the unknowns [begin, end) (one solid body, 3 per node) that
  /// AMG takes; the near-null space and the coordinates above are then that
  /// block's (end − begin rows, and (end − begin)/3). Ignored by the others.
  virtual void set_amg_block(std::int64_t begin, std::int64_t end) {}
  /// Krylov solvers: the relative residual at which the following solves stop
  /// (an inexact Newton's forcing term), never tighter than the settings'
  /// tolerance; 0 restores that. Returns false for direct solvers, which ignore it.
  virtual bool set_relative_tolerance(double tolerance) { return false; }
  virtual std::string describe() const = 0;
};

std::unique_ptr<LinearSolver> make_linear_solver(const LinearSolverSettings& settings);
/// Initialises MPI (through Tpetra, as the Trilinos solvers do) unless it is already,
/// so a process started by mpirun knows its rank and the rank count whatever solver it
/// runs (eigen_lu alone never touches MPI).
void initialize_parallel();

/// The Eigen SparseLU reference solver (single rank).
std::unique_ptr<LinearSolver> make_eigen_lu_solver();
/// SuiteSparse UMFPACK sparse LU (single rank; keeps the symbolic analysis
/// while the pattern stays the same).
std::unique_ptr<LinearSolver> make_umfpack_solver();
/// direct (UMFPACK; on several ranks the matrix is gathered on rank 0),
/// gmres_ilu, gmres_amg, gmres_amg_block, gmres_lu.
std::unique_ptr<LinearSolver> make_trilinos_solver(const LinearSolverSettings& settings);

}  // namespace stentsim::solver
