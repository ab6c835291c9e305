#include "fibers/laplace_field.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <chrono>
#include <vector>

#include "common/error.hpp"
#include "solver/assembly/constraints.hpp"
#include "solver/assembly/global_system.hpp"
#include "solver/fem/elements.hpp"
#include "solver/linalg/linear_solver.hpp"

namespace stentsim::fibers {
namespace {
namespace fem = solver::fem;

template <class E>
Eigen::Matrix<double, E::kNodes, 3> coords(const MeshData& mesh, const std::vector<std::int64_t>& nodes) {
  Eigen::Matrix<double, E::kNodes, 3> x;
  for (int a = 0; a < E::kNodes; ++a) x.row(a) = mesh.points[static_cast<std::size_t>(nodes[static_cast<std::size_t>(a)])].transpose();
  return x;
}

/// Spatial shape gradients at xi (rows: nodes) and det J; det J <= 0 is an
/// inverted element and an error, since the harmonic field would be wrong there.
template <class E>
Eigen::Matrix<double, E::kNodes, 3> spatial_gradients(const Eigen::Matrix<double, E::kNodes, 3>& x,
                                                       const std::array<double, 3>& xi, std::size_t cell,
                                                       double* det = nullptr) {
  const auto s = E::eval(xi);
  const Eigen::Matrix3d j = x.transpose() * s.dn;  // dX_i/dxi_k
  const double d = j.determinant();
  if (!(d > 0)) throw ComputeError(fmt::format("fibers: {} cell {} has det J = {:.3g} (inverted or degenerate)", E::kName, cell, d));
  if (det) *det = d;
  return s.dn * j.inverse();
}

template <class E>
void add_element(const MeshData& mesh, std::size_t c, solver::GlobalSystem& sys) {
  const auto nodes = mesh.cell(c);
  const auto x = coords<E>(mesh, nodes);
  Eigen::Matrix<double, E::kNodes, E::kNodes> k = Eigen::Matrix<double, E::kNodes, E::kNodes>::Zero();
  for (int q = 0; q < E::kRule.kPoints; ++q) {
    double det = 0;
    const auto g = spatial_gradients<E>(x, E::kRule.points[q], c, &det);
    k.noalias() += (E::kRule.weights[q] * det) * g * g.transpose();
  }
  std::array<solver::GlobalDof, E::kNodes> dofs;
  for (int a = 0; a < E::kNodes; ++a) dofs[static_cast<std::size_t>(a)] = nodes[static_cast<std::size_t>(a)];
  const Eigen::VectorXd r = Eigen::VectorXd::Zero(E::kNodes);  // the state is u = 0
  const Eigen::MatrixXd kd = k;
  sys.add(dofs, r, kd);
}

template <class E>
std::array<double, 3> centroid_xi() {
  if constexpr (E::kCell == CellType::hexahedron) return {0.0, 0.0, 0.0};
  else return {0.25, 0.25, 0.25};
}

template <class F>
auto dispatch(CellType t, F&& f) {
  switch (t) {
    case CellType::hexahedron: return f(fem::Hex8{});
    case CellType::tetra: return f(fem::Tet4{});
    case CellType::quadratic_tetra: return f(fem::Tet10{});
    default: throw InputError(fmt::format("fibers: cell type {} is not a volume cell", static_cast<int>(t)));
  }
}
}  // namespace

bool is_volume_cell(CellType t) {
  return t == CellType::hexahedron || t == CellType::tetra || t == CellType::quadratic_tetra;
}

LaplaceSolve solve_laplace(const MeshData& mesh, const std::map<std::int64_t, double>& dirichlet,
                           solver::LinearSolverType solver_type) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto n = static_cast<solver::GlobalDof>(mesh.points.size());
  // Points no volume cell touches (none in a clean mesh) get an identity row.
  std::vector<char> used(mesh.points.size(), 0);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c)
    if (is_volume_cell(mesh.cell_types[c]))
      for (auto p : mesh.cell(c)) used[static_cast<std::size_t>(p)] = 1;
  solver::Constraints constraints(n);
  Eigen::VectorXd prescribed = Eigen::VectorXd::Zero(n);
  for (const auto& [node, value] : dirichlet) {
    const double v = value;
    constraints.fix(node, [v](double) { return v; });
    prescribed(node) = v;
  }
  for (std::size_t p = 0; p < used.size(); ++p)
    if (!used[p] && !constraints.fixed(static_cast<solver::GlobalDof>(p)))
      constraints.fix(static_cast<solver::GlobalDof>(p), [](double) { return 0.0; });

  solver::GlobalSystem sys(constraints);
  sys.begin(prescribed, true);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (!is_volume_cell(mesh.cell_types[c])) continue;
    dispatch(mesh.cell_types[c], [&](auto e) { add_element<decltype(e)>(mesh, c, sys); });
  }
  sys.finish();
  const auto t1 = std::chrono::steady_clock::now();

  solver::LinearSolverSettings ls;
  ls.type = solver_type;
  ls.tolerance = 1e-10;
  ls.max_iterations = 5000;
  ls.ilu_fill = 1;  // a scalar Laplace problem: ILU(1) converges in few iterations and sets up fast (ILU(4) does not pay off)
  ls.amg_equations_per_node = 1;  // gmres_amg: scalar unknowns, constant near-null space
  auto linear = solver::make_linear_solver(ls);
  LaplaceSolve out;
  out.u = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd b = sys.rhs();
  const auto stats = linear->solve(sys.matrix(), b, out.u);
  if (!stats.converged)
    throw ComputeError(fmt::format("fibers: the Laplace solve ({}) did not converge: relative residual {:.3g} after {} iterations",
                                   linear->describe(), stats.relative_residual, stats.iterations));
  // Dirichlet nodes hold their values exactly (an iterative solve meets the
  // identity rows only to its tolerance).
  for (const auto& [node, value] : dirichlet) out.u(node) = value;
  // The residual of the assembled system, independent of the solver's own measure.
  const double bn = b.norm();
  out.relative_residual = bn > 0 ? (sys.matrix().multiply(out.u) - b).norm() / bn : 0.0;
  out.iterations = stats.iterations;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.assembly_seconds = std::chrono::duration<double>(t1 - t0).count();
  out.setup_seconds = stats.setup_seconds;
  out.solve_seconds = stats.solve_seconds;
  return out;
}

Eigen::Vector3d centroid_gradient(const MeshData& mesh, std::size_t c, const Eigen::VectorXd& u) {
  return dispatch(mesh.cell_types[c], [&](auto e) -> Eigen::Vector3d {
    using E = decltype(e);
    const auto nodes = mesh.cell(c);
    const auto g = spatial_gradients<E>(coords<E>(mesh, nodes), centroid_xi<E>(), c);
    Eigen::Matrix<double, E::kNodes, 1> ue;
    for (int a = 0; a < E::kNodes; ++a) ue(a) = u(nodes[static_cast<std::size_t>(a)]);
    return g.transpose() * ue;
  });
}

double centroid_value(const MeshData& mesh, std::size_t c, const Eigen::VectorXd& u) {
  return dispatch(mesh.cell_types[c], [&](auto e) -> double {
    using E = decltype(e);
    const auto nodes = mesh.cell(c);
    const auto s = E::eval(centroid_xi<E>());
    double v = 0;
    for (int a = 0; a < E::kNodes; ++a) v += s.n(a) * u(nodes[static_cast<std::size_t>(a)]);
    return v;
  });
}

}  // namespace stentsim::fibers
