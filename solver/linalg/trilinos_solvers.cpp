// Trilinos adapter (compiled as C++17: Teuchos 13.2 does not build as C++20).
// Tpetra CrsMatrix from the assembled CSR (rows summed over ranks by
// fillComplete), then ("direct" on several ranks) gathered on rank 0 for
// UMFPACK, or Belos block GMRES preconditioned by
// Ifpack2 RILUK (ILU(k); additive Schwarz over ranks) or MueLu smoothed
// aggregation with the rigid-body near-null space (paper Section 4.2.1:
// GMRES, ILU(4), Krylov space 200).
#include <BelosBlockGmresSolMgr.hpp>
#include <BelosLinearProblem.hpp>
#include <BelosTpetraAdapter.hpp>
#include <Ifpack2_Factory.hpp>
#include <MueLu_CreateTpetraPreconditioner.hpp>
#include <MueLu_Hierarchy.hpp>
#include <MueLu_TpetraOperator.hpp>
#include <Teuchos_ParameterList.hpp>
#include <Teuchos_XMLParameterListHelpers.hpp>
#include <Tpetra_Core.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Export.hpp>
#include <Tpetra_MultiVector.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/linalg/block_split.hpp"
#include "solver/linalg/lag_policy.hpp"
#include "solver/linalg/linear_solver.hpp"
#include "solver/linalg/umfpack_factor.hpp"

namespace stentsim::solver {
namespace {

using SC = double;
using LO = Tpetra::Map<>::local_ordinal_type;
using GO = Tpetra::Map<>::global_ordinal_type;
using NO = Tpetra::Map<>::node_type;
using Map = Tpetra::Map<LO, GO, NO>;
using Matrix = Tpetra::CrsMatrix<SC, LO, GO, NO>;
using MV = Tpetra::MultiVector<SC, LO, GO, NO>;
using OP = Tpetra::Operator<SC, LO, GO, NO>;
using Teuchos::RCP;
using Teuchos::rcp;

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

void ensure_initialized() {
  if (Tpetra::isInitialized()) return;
  static int argc = 1;
  static char name[] = "stentsim";
  static char* args[] = {name, nullptr};
  static char** argv = args;
  Tpetra::initialize(&argc, &argv);
  std::atexit([] { Tpetra::finalize(); });
}

// A fill-complete Tpetra matrix kept with the CSR pattern it was built from
// (one rank). On one rank the column map is the row map, in order, so the
// matrix's packed local values lie in the CSR's own order: new values of the
// same pattern are copied straight in (replaceGlobalValues would look every
// column up in the column map's hash table, which costs more than the assembly
// on a tet10 artery). keep() checks that order once; where it does not hold,
// the matrix is not kept and each solve builds its own.
struct KeptMatrix {
  RCP<Matrix> matrix;
  std::vector<std::int64_t> row_ptr, cols;

  bool holds(const CsrMatrix& a) const { return matrix && a.row_ptr == row_ptr && a.cols == cols; }

  void keep(RCP<Matrix> m, const CsrMatrix& a) {
    matrix = Teuchos::null;
    const auto local = m->getLocalMatrixHost();
    const Map& colmap = *m->getColMap();
    if (static_cast<std::int64_t>(local.numRows()) != a.rows) return;
    for (std::int64_t i = 0; i < a.rows; ++i) {
      const auto b = a.row_ptr[static_cast<std::size_t>(i)], e = a.row_ptr[static_cast<std::size_t>(i) + 1];
      if (static_cast<std::int64_t>(local.graph.row_map(i)) != b || static_cast<std::int64_t>(local.graph.row_map(i + 1)) != e)
        return;
      for (auto k = b; k < e; ++k)
        if (colmap.getGlobalElement(local.graph.entries(k)) != static_cast<GO>(a.cols[static_cast<std::size_t>(k)])) return;
    }
    matrix = std::move(m);
    row_ptr = a.row_ptr;
    cols = a.cols;
  }

  /// New values of the kept pattern (holds(a) must be true).
  void refill(const CsrMatrix& a) { refill(a.values); }
  /// New values in the kept pattern's order.
  void refill(const std::vector<double>& v) {
    matrix->resumeFill();
    {
      const auto values = matrix->getLocalMatrixHost().values;
      for (std::size_t k = 0; k < v.size(); ++k) values(k) = v[k];
    }
    matrix->fillComplete();
  }
};

// y = alpha * v + beta * y for one entry of an operator's output; beta = 0
// overwrites y (which may hold garbage, Tpetra's convention).
double scaled_output(double v, double y, SC alpha, SC beta) { return beta == 0.0 ? alpha * v : alpha * v + beta * y; }

// gmres_amg_block's preconditioner (block_split.hpp): one forward block
// Gauss-Seidel sweep, AMG on block 1 then the direct solve of block 2 (one rank).
class BlockGaussSeidel : public OP {
 public:
  BlockGaussSeidel(RCP<const Map> map, RCP<const Map> map1, RCP<OP> amg, const BlockSplit& split, const UmfpackFactor& lu)
      : map_(std::move(map)), map1_(std::move(map1)), amg_(std::move(amg)), split_(split), lu_(lu) {}
  RCP<const Map> getDomainMap() const override { return map_; }
  RCP<const Map> getRangeMap() const override { return map_; }
  void apply(const MV& x, MV& y, Teuchos::ETransp mode = Teuchos::NO_TRANS, SC alpha = Teuchos::ScalarTraits<SC>::one(),
             SC beta = Teuchos::ScalarTraits<SC>::zero()) const override {
    if (mode != Teuchos::NO_TRANS) throw std::logic_error("gmres_amg_block: the preconditioner has no transpose");
    const std::int64_t n1 = split_.end - split_.begin, n2 = split_.a22.rows;
    MV r1(map1_, 1), y1(map1_, 1);
    Eigen::VectorXd y1e(n1), r2(n2), y2;
    for (std::size_t j = 0; j < x.getNumVectors(); ++j) {
      const auto xd = x.getData(j);
      {
        auto rd = r1.getDataNonConst(0);
        for (std::int64_t i = 0; i < n1; ++i) rd[i] = xd[split_.begin + i];
      }
      amg_->apply(r1, y1);
      {
        const auto yd = y1.getData(0);
        for (std::int64_t i = 0; i < n1; ++i) y1e(i) = yd[i];
      }
      for (std::int64_t k = 0; k < n2; ++k) r2(k) = xd[split_.full_of_outer(k)];
      r2 -= split_.a21.multiply(y1e);
      lu_.solve(r2, y2);
      auto out = y.getDataNonConst(j);
      auto put = [&](std::int64_t i, double v) { out[i] = scaled_output(v, out[i], alpha, beta); };
      for (std::int64_t i = 0; i < n1; ++i) put(split_.begin + i, y1e(i));
      for (std::int64_t k = 0; k < n2; ++k) put(split_.full_of_outer(k), y2(k));
    }
  }

 private:
  RCP<const Map> map_, map1_;
  RCP<OP> amg_;
  const BlockSplit& split_;
  const UmfpackFactor& lu_;
};

// gmres_lu's preconditioner: the UMFPACK factors of the whole matrix (of this
// solve's or, lagged, an earlier one's).
class LuOperator : public OP {
 public:
  LuOperator(RCP<const Map> map, const UmfpackFactor& lu) : map_(std::move(map)), lu_(lu) {}
  RCP<const Map> getDomainMap() const override { return map_; }
  RCP<const Map> getRangeMap() const override { return map_; }
  void apply(const MV& x, MV& y, Teuchos::ETransp mode = Teuchos::NO_TRANS, SC alpha = Teuchos::ScalarTraits<SC>::one(),
             SC beta = Teuchos::ScalarTraits<SC>::zero()) const override {
    if (mode != Teuchos::NO_TRANS) throw std::logic_error("gmres_lu: the preconditioner has no transpose");
    const auto n = static_cast<Eigen::Index>(lu_.rows());
    Eigen::VectorXd r(n), z;
    for (std::size_t j = 0; j < x.getNumVectors(); ++j) {
      const auto xd = x.getData(j);
      for (Eigen::Index i = 0; i < n; ++i) r(i) = xd[i];
      lu_.solve(r, z);
      auto out = y.getDataNonConst(j);
      for (Eigen::Index i = 0; i < n; ++i) out[i] = scaled_output(z(i), out[i], alpha, beta);
    }
  }

 private:
  RCP<const Map> map_;
  const UmfpackFactor& lu_;
};

class TrilinosSolver : public LinearSolver {
 public:
  explicit TrilinosSolver(LinearSolverSettings s) : settings_(std::move(s)) {
    ensure_initialized();
    comm_ = Tpetra::getDefaultComm();
  }

  void set_near_null_space(const Eigen::MatrixXd& modes) override { modes_ = modes; }
  void set_node_coordinates(const Eigen::MatrixXd& xyz) override { coordinates_ = xyz; }
  void set_amg_block(std::int64_t begin, std::int64_t end) override { block_begin_ = begin, block_end_ = end; }

  bool set_relative_tolerance(double tolerance) override {
    requested_tolerance_ = tolerance;
    return settings_.type != LinearSolverType::direct;
  }

  std::string describe() const override {
    if (settings_.type == LinearSolverType::direct)
      return comm_->getSize() > 1 ? "direct: matrix gathered on rank 0, UMFPACK sparse LU there (serial)" : "UMFPACK sparse LU (direct)";
    std::ostringstream o;
    o << "Belos block GMRES (Krylov space " << settings_.krylov_size << ", tol " << settings_.tolerance << ") + ";
    if (settings_.type == LinearSolverType::gmres_ilu) o << "Ifpack2 ILU(" << settings_.ilu_fill << ")";
    else if (settings_.type == LinearSolverType::gmres_amg_block)
      o << "block Gauss-Seidel: MueLu smoothed-aggregation AMG on unknowns [" << block_begin_ << ", " << block_end_
        << "), UMFPACK LU on the others";
    else if (settings_.type == LinearSolverType::gmres_lu)
      o << "UMFPACK LU of the whole matrix" << (settings_.lag_preconditioner ? ", kept for later matrices while that pays" : "");
    else if (settings_.amg_equations_per_node == 1) o << "MueLu smoothed-aggregation AMG (scalar, constant near-null space, symmetric Gauss-Seidel)";
    else o << "MueLu smoothed-aggregation AMG (" << settings_.amg_equations_per_node << " equations per node, symmetric Gauss-Seidel)";
    if (settings_.type != LinearSolverType::gmres_ilu && !settings_.amg_parameters.empty())
      o << ", MueLu parameters from " << settings_.amg_parameters;
    return o.str();
  }

  LinearSolveStats solve(const CsrMatrix& a, const Eigen::VectorXd& b, Eigen::VectorXd& x) override {
    // One rank: its contributions are the whole matrix, no Tpetra copy needed.
    if (settings_.type == LinearSolverType::direct && comm_->getSize() == 1) return direct_->solve(a, b, x);
    const bool block = settings_.type == LinearSolverType::gmres_amg_block;
    const bool whole_lu = settings_.type == LinearSolverType::gmres_lu;
    if (one_rank_only(settings_.type) && comm_->getSize() > 1)  // solve() refuses such a scene first
      throw std::logic_error("linear solver " + linear_solver_name(settings_.type) + " on " + std::to_string(comm_->getSize()) + " ranks");
    LinearSolveStats stats;
    const auto t0 = Clock::now();
    const GO n = static_cast<GO>(a.rows);
    // ILU(k) on one rank: RILUK's symbolic factorization (the level-of-fill
    // pattern, initialize()) depends on the pattern only and is ~3/4 of its
    // set-up (Case 1 artery, ILU(4): 15 s of 20 s). While the pattern stays,
    // the Tpetra matrix is refilled in place and only compute() is redone.
    // (Not on several ranks: AdditiveSchwarz imports the overlap rows in
    // initialize() only, so a refilled matrix would leave them stale.)
    //
    // AMG on one rank likewise: while the pattern stays, the hierarchy's
    // prolongators (aggregates and their smoothing, ~2/3 of its set-up) are kept
    // and only the coarse operators RAP and the smoothers are recomputed from the
    // new values (MueLu "reuse: type" RP). For a solid scene that is the whole run:
    // the aggregates depend on the pattern and the near-null space only, the
    // prolongator's smoothing on the first matrix's values (the peer tube's GMRES
    // counts stayed as after a fresh set-up over its 20 steps; a test bounds the
    // cost of a matrix whose anisotropy turns, test_solver_linear_reuse).
    //
    // gmres_amg_block keeps the whole matrix likewise, block 1's AMG prolongators
    // while block 1's pattern stays and block 2's LU analysis while block 2's does
    // (block_preconditioner).
    const bool keep = settings_.type != LinearSolverType::direct && comm_->getSize() == 1;
    const bool reuse = keep && kept_.holds(a);
    RCP<const Map> map;
    RCP<Matrix> mat;
    if (reuse) {
      map = kept_.matrix->getRowMap();
      mat = kept_.matrix;
      kept_.refill(a);
    } else {
      map = rcp(new Map(n, 0, comm_));
      mat = build_matrix(a, map);
    }
    RCP<MV> bv = rcp(new MV(map, 1)), xv = rcp(new MV(map, 1));
    for (LO i = 0; i < static_cast<LO>(map->getNodeNumElements()); ++i) bv->replaceLocalValue(i, 0, b(map->getGlobalElement(i)));
    xv->putScalar(0.0);

    if (settings_.type == LinearSolverType::direct && comm_->getSize() > 1) {
      // Amesos2 has only KLU2 and Tacho here, and KLU2 on a distributed matrix
      // returned wrong solutions with Debian's Trilinos 13.2 (caught by
      // test_solver_mpi_two_ranks): gather the assembled matrix on rank 0,
      // factor it there with UMFPACK and broadcast.
      stats = gathered_direct_solve(mat, map, b, x);
      stats.lu_factorizations = 1;
      stats.setup_seconds = seconds(t0, Clock::now()) - stats.solve_seconds;  // matrix, gather, factorization, broadcast
      return stats;
    }
    // A lagged preconditioner (lag_preconditioner, LagPolicy): AMG's hierarchy (with its
    // smoothers and coarse operators), ILU's or LU's factors as the last set-up left them.
    // gmres_amg_block lags block 1's AMG and block 2's LU, gmres_lu its factors; these work on any
    // matrix of the same size (AMG holds its own matrix, the LU solves read the factors
    // only); gmres_amg's and gmres_ilu's are bound to the kept matrix, so they serve only a
    // matrix of its pattern. A failed factorization leaves no factors to lag (rows() -1).
    const bool any_pattern = block || whole_lu;
    const bool held = block      ? block_amg_ && block_lu_.rows() == a.rows - (block_end_ - block_begin_)
                      : whole_lu ? whole_lu_.rows() == a.rows && kept_prec_
                                 : reuse && kept_prec_;
    const bool lag = settings_.lag_preconditioner && keep && lag_.may_lag() && held;
    RCP<OP> prec;
    const auto tp = Clock::now();
    if (lag) {
      prec = block ? block_preconditioner(a, map, stats, false) : whole_lu ? RCP<OP>(new LuOperator(map, whole_lu_)) : kept_prec_;
      stats.preconditioner_lagged = true;
      if (any_pattern && !reuse) kept_.keep(mat, a);
    } else {
      prec = fresh_preconditioner(a, mat, map, reuse, keep, stats);
    }
    auto t1 = Clock::now();
    stats.setup_seconds = seconds(t0, t1);
    const double tolerance = std::max(settings_.tolerance, requested_tolerance_);
    GmresResult g = gmres(mat, prec, xv, bv, lag ? lag_.iteration_cap(tolerance, settings_.max_iterations) : settings_.max_iterations,
                          tolerance);
    stats.solve_seconds = seconds(t1, Clock::now());
    if (lag && !g.converged) {
      // The lagged preconditioner no longer serves this matrix: a fresh one, and GMRES goes
      // on from where the lagged solve stopped (to the rest of the tolerance, relative to
      // the residual it starts from), so the lagged iterations are not lost.
      log::debug("GMRES with the lagged preconditioner stopped at {:.2e} after {} iterations; going on with a fresh one",
                 g.achieved, g.iterations);
      const auto t2 = Clock::now();
      stats.preconditioner_lagged = false;
      prec = fresh_preconditioner(a, mat, map, true, keep, stats);  // lagging implies the matrix is kept
      const auto t3 = Clock::now();
      const GmresResult first = g;
      const double rest = first.achieved > tolerance ? tolerance / first.achieved : 1.0;
      g = gmres(mat, prec, xv, bv, settings_.max_iterations, rest);
      lag_.built(block ? block_amg_seconds_ + block_lu_seconds_ : seconds(t2, t3), g.iterations, g.achieved, seconds(t3, Clock::now()));
      g.iterations += first.iterations;
      g.achieved *= first.achieved;
      stats.setup_seconds += seconds(t2, t3);
      stats.solve_seconds += seconds(t3, Clock::now());
    } else if (!lag) {
      lag_.built(block ? block_amg_seconds_ + block_lu_seconds_ : seconds(tp, t1), g.iterations, g.achieved, stats.solve_seconds);
    } else {
      lag_.lagged(g.iterations, g.achieved, stats.solve_seconds);
    }
    stats.iterations = g.iterations;
    stats.converged = g.converged;
    // Relative residual, and the full solution on every rank.
    MV r(map, 1);
    mat->apply(*xv, r);
    r.update(1.0, *bv, -1.0);
    Teuchos::Array<SC> rn(1), bn(1);
    r.norm2(rn());
    bv->norm2(bn());
    stats.relative_residual = bn[0] > 0 ? rn[0] / bn[0] : rn[0];
    Eigen::VectorXd local = Eigen::VectorXd::Zero(a.rows);
    auto xd = xv->getData(0);
    for (LO i = 0; i < static_cast<LO>(map->getNodeNumElements()); ++i) local(map->getGlobalElement(i)) = xd[i];
    x.resize(a.rows);
    Teuchos::reduceAll<int, double>(*comm_, Teuchos::REDUCE_SUM, static_cast<int>(a.rows), local.data(), x.data());
    if (!x.allFinite()) stats.converged = false;
    return stats;
  }

 private:
  struct GmresResult {
    int iterations = 0;
    bool converged = false;
    double achieved = 1.0;  // Belos's achieved relative residual
  };

  // GMRES from the guess in `x` to `tolerance` relative to its initial residual.
  GmresResult gmres(const RCP<Matrix>& mat, const RCP<OP>& prec, const RCP<MV>& x, const RCP<MV>& b, int max_iterations,
                    double tolerance) const {
    auto problem = rcp(new Belos::LinearProblem<SC, MV, OP>(mat, x, b));
    problem->setRightPrec(prec);
    if (!problem->setProblem()) throw std::runtime_error("Belos: could not set up the linear problem");
    auto params = rcp(new Teuchos::ParameterList);
    params->set("Num Blocks", settings_.krylov_size);
    params->set("Maximum Iterations", max_iterations);
    params->set("Maximum Restarts", std::max(1, max_iterations / std::max(1, settings_.krylov_size)));
    params->set("Convergence Tolerance", tolerance);
    params->set("Verbosity", settings_.verbosity > 0 ? Belos::Errors + Belos::Warnings + Belos::FinalSummary : Belos::Errors);
    Belos::BlockGmresSolMgr<SC, MV, OP> solver(problem, params);
    GmresResult r;
    r.converged = solver.solve() == Belos::Converged;
    r.iterations = solver.getNumIters();
    r.achieved = solver.achievedTol();
    return r;
  }

  // A preconditioner set up for `mat` (values of `a`): built, or (`reuse`: the
  // matrix is the kept one, refilled) the kept one recomputed from the new values.
  RCP<OP> fresh_preconditioner(const CsrMatrix& a, const RCP<Matrix>& mat, const RCP<const Map>& map, bool reuse, bool keep,
                               LinearSolveStats& stats) {
    if (settings_.type == LinearSolverType::gmres_amg_block) {
      RCP<OP> prec = block_preconditioner(a, map, stats, true);
      if (!reuse) kept_.keep(mat, a);
      return prec;
    }
    if (settings_.type == LinearSolverType::gmres_lu) {
      kept_prec_ = Teuchos::null;  // a failed factorization leaves nothing to lag
      whole_lu_.factor(a);         // its symbolic analysis kept while the pattern stays
      stats.preconditioner_built = true;
      ++stats.lu_factorizations;
      kept_prec_ = rcp(new LuOperator(map, whole_lu_));
      if (!reuse) kept_.keep(mat, a);
      return kept_prec_;
    }
    if (reuse) {
      if (auto ilu = Teuchos::rcp_dynamic_cast<Ifpack2::Preconditioner<SC, LO, GO, NO>>(kept_prec_)) {
        ilu->compute();
      } else {
        auto amg = Teuchos::rcp_dynamic_cast<MueLu::TpetraOperator<SC, LO, GO, NO>>(kept_prec_, true);
        if (!reuse_amg(mat, *amg)) kept_prec_ = make_preconditioner(mat, map, stats, true);
        stats.amg_levels = Teuchos::rcp_dynamic_cast<MueLu::TpetraOperator<SC, LO, GO, NO>>(kept_prec_, true)
                               ->GetHierarchy()->GetNumLevels();
      }
      return kept_prec_;
    }
    RCP<OP> prec = make_preconditioner(mat, map, stats, keep);
    if (keep) {
      kept_prec_ = prec;
      kept_.keep(mat, a);
    }
    return prec;
  }

  RCP<Matrix> build_matrix(const CsrMatrix& a, const RCP<const Map>& map) const {
    if (comm_->getSize() == 1) {
      if (RCP<Matrix> m = local_matrix(a, map); !m.is_null()) return m;
    }
    // Capacity per owned row: the sum over ranks of their entries in it (an
    // upper bound of the union that fillComplete assembles).
    const std::size_t local_rows = map->getNodeNumElements();
    Teuchos::Array<std::size_t> capacity(local_rows, 0);
    std::vector<long long> counts(static_cast<std::size_t>(a.rows)), total(static_cast<std::size_t>(a.rows));
    for (std::int64_t i = 0; i < a.rows; ++i) counts[static_cast<std::size_t>(i)] = a.row_ptr[static_cast<std::size_t>(i) + 1] - a.row_ptr[static_cast<std::size_t>(i)];
    if (comm_->getSize() > 1)
      Teuchos::reduceAll<int, long long>(*comm_, Teuchos::REDUCE_SUM, static_cast<int>(a.rows), counts.data(), total.data());
    else
      total = counts;
    for (std::size_t i = 0; i < local_rows; ++i)
      capacity[i] = static_cast<std::size_t>(std::max(1LL, total[static_cast<std::size_t>(map->getGlobalElement(static_cast<LO>(i)))]));
    RCP<Matrix> m = rcp(new Matrix(map, capacity()));
    Teuchos::Array<GO> cols;
    for (std::int64_t i = 0; i < a.rows; ++i) {
      const auto b = a.row_ptr[static_cast<std::size_t>(i)], e = a.row_ptr[static_cast<std::size_t>(i) + 1];
      if (b == e) continue;
      cols.resize(static_cast<std::size_t>(e - b));
      for (auto k = b; k < e; ++k) cols[static_cast<std::size_t>(k - b)] = static_cast<GO>(a.cols[static_cast<std::size_t>(k)]);
      m->insertGlobalValues(static_cast<GO>(i), cols(), Teuchos::ArrayView<const SC>(&a.values[static_cast<std::size_t>(b)], e - b));
    }
    m->fillComplete();
    return m;
  }

  // One rank, columns sorted in every row (GlobalSystem's pattern): the CSR arrays are the
  // local matrix itself, with the row Map as column Map (local column = global column).
  // insertGlobalValues and fillComplete would sort, merge and hash every entry again
  // (1.3 s for the 10 M entries of the bundled patient, paid at each growth of the
  // contact pattern). Null when a row's columns are not strictly increasing or not all
  // inside the matrix (the constructor takes them on trust; insertGlobalValues checks them).
  RCP<Matrix> local_matrix(const CsrMatrix& a, const RCP<const Map>& map) const {
    const auto rows = static_cast<std::size_t>(a.rows), nnz = a.cols.size();
    Teuchos::ArrayRCP<std::size_t> ptr(rows + 1);
    Teuchos::ArrayRCP<LO> ind(nnz);
    Teuchos::ArrayRCP<SC> val(nnz);
    for (std::size_t i = 0; i <= rows; ++i) ptr[i] = static_cast<std::size_t>(a.row_ptr[i]);
    for (std::size_t i = 0; i < rows; ++i)
      for (auto k = ptr[i]; k < ptr[i + 1]; ++k) {
        if ((k > ptr[i] && a.cols[k] <= a.cols[k - 1]) || a.cols[k] < 0 || a.cols[k] >= a.rows) return Teuchos::null;
        ind[k] = static_cast<LO>(a.cols[k]);
      }
    std::copy(a.values.begin(), a.values.end(), val.begin());
    RCP<Matrix> m = rcp(new Matrix(map, map, ptr, ind, val));
    m->expertStaticFillComplete(map, map);
    return m;
  }

  LinearSolveStats gathered_direct_solve(const RCP<Matrix>& mat, const RCP<const Map>& map, const Eigen::VectorXd& b,
                                         Eigen::VectorXd& x) const {
    const GO n = static_cast<GO>(map->getGlobalNumElements());
    const bool root = comm_->getRank() == 0;
    RCP<const Map> gmap = rcp(new Map(n, root ? static_cast<std::size_t>(n) : 0, 0, comm_));
    RCP<Matrix> gathered = rcp(new Matrix(gmap, 0));
    Tpetra::Export<LO, GO, NO> exporter(map, gmap);
    gathered->doExport(*mat, exporter, Tpetra::INSERT);
    gathered->fillComplete(gmap, gmap);
    LinearSolveStats stats;
    std::string failure;
    x = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
    if (root) {
      // Everything on rank 0 inside the try: an exception there must reach the
      // other ranks, which would otherwise wait in the broadcast below.
      try {
        CsrMatrix a;
        a.rows = n;
        a.row_ptr.assign(static_cast<std::size_t>(n) + 1, 0);
        Teuchos::Array<GO> cols(gathered->getGlobalMaxNumRowEntries());
        Teuchos::Array<SC> vals(gathered->getGlobalMaxNumRowEntries());
        for (GO i = 0; i < n; ++i) {
          std::size_t count = 0;
          gathered->getGlobalRowCopy(i, cols(), vals(), count);
          std::vector<std::pair<GO, SC>> row;
          for (std::size_t k = 0; k < count; ++k) row.emplace_back(cols[k], vals[k]);
          std::sort(row.begin(), row.end());
          for (const auto& [c, v] : row) a.cols.push_back(c), a.values.push_back(v);
          a.row_ptr[static_cast<std::size_t>(i) + 1] = static_cast<std::int64_t>(a.cols.size());
        }
        stats = direct_->solve(a, b, x);
      } catch (const std::exception& e) {
        failure = e.what();  // thrown on every rank below: the others would wait in the broadcast
      }
    }
    int failed = failure.empty() ? 0 : 1;
    Teuchos::broadcast<int, int>(*comm_, 0, 1, &failed);
    if (failed) throw std::runtime_error(root ? failure : "the direct solve on rank 0 failed");
    Teuchos::broadcast<int, double>(*comm_, 0, static_cast<int>(n), x.data());
    int ok = stats.converged ? 1 : 0;
    Teuchos::broadcast<int, int>(*comm_, 0, 1, &ok);
    stats.converged = ok != 0;
    stats.iterations = 1;
    return stats;
  }

  // gmres_amg_block: split, AMG on block 1 (its prolongators kept while its
  // pattern stays, as gmres_amg's), UMFPACK on block 2 (its analysis kept likewise).
  // `refresh_amg` false (lagged): block 1's AMG and block 2's LU as the last set-up
  // left them, the split (the coupling block A21 of the sweep) this matrix's.
  RCP<OP> block_preconditioner(const CsrMatrix& a, const RCP<const Map>& map, LinearSolveStats& stats, bool refresh_amg) {
    if (block_end_ <= block_begin_)
      throw std::logic_error("gmres_amg_block: no AMG block was set (set_amg_block)");
    split_blocks(a, block_begin_, block_end_, split_);
    if (refresh_amg || !block_amg_) {
      const auto t0 = Clock::now();
      // The AMG's A11 keeps the pattern its hierarchy was built on (amg_matrix, block_split.hpp).
      bool same = block_amg_ && block_.matrix && amg_values_on(split_.a11, block_.row_ptr, block_.cols, amg_values_);
      if (same) {
        block_.refill(amg_values_);
        same = reuse_amg(block_.matrix, *block_amg_);
        block_map_ = block_.matrix->getRowMap();
      }
      if (!same) {
        const CsrMatrix m11 = amg_matrix(split_.a11);
        block_map_ = rcp(new Map(static_cast<GO>(m11.rows), 0, comm_));
        RCP<Matrix> m = build_matrix(m11, block_map_);
        block_amg_ = Teuchos::rcp_dynamic_cast<MueLu::TpetraOperator<SC, LO, GO, NO>>(
            make_preconditioner(m, block_map_, stats, true), true);
        block_.keep(m, m11);
      }
      block_amg_seconds_ = seconds(t0, Clock::now());
    }
    stats.amg_levels = block_amg_->GetHierarchy()->GetNumLevels();
    // Block 2's LU is lagged with block 1's AMG (LagPolicy is charged both set-ups):
    // solves read the factors only, so those of an earlier a22 serve any later one of
    // its size (the contact entries between balloon and stent come and go).
    if (refresh_amg || block_lu_.rows() != split_.a22.rows) {
      const auto t0 = Clock::now();
      block_lu_.factor(split_.a22);
      ++stats.lu_factorizations;
      block_lu_seconds_ = seconds(t0, Clock::now());
    }
    return rcp(new BlockGaussSeidel(map, block_map_, block_amg_, split_, block_lu_));
  }

  // The kept hierarchy's prolongators with the new values (MueLu reuse RP).
  // Contact terms reserve entries that stay exactly zero until a point comes
  // within reach; the kept coarse operators' static graphs miss the products of
  // such entries once they fill (Tpetra: "insert a new entry into a static
  // graph"). False then: the caller builds the hierarchy afresh.
  bool reuse_amg(const RCP<Matrix>& m, MueLu::TpetraOperator<SC, LO, GO, NO>& amg) const {
    try {
      MueLu::ReuseTpetraPreconditioner(m, amg);
      return true;
    } catch (const std::exception& e) {
      const std::string what = e.what();
      if (what.find("static graph") == std::string::npos) throw;
      log::debug("AMG: the kept hierarchy does not take the new values (newly filled entries); building it afresh");
      return false;
    }
  }

  // SA-AMG needs a near-null space that describes every row with the fixed
  // block size: a silently dropped or partly zero null space gives a coarse
  // space without the rigid-body modes (slow or stalled GMRES) and no message.
  void check_near_null_space(GO n) const {
    const int eq = settings_.amg_equations_per_node;
    if (eq > 1 && n % eq != 0)
      throw InputError("gmres_amg: " + std::to_string(n) + " unknowns are not a multiple of " + std::to_string(eq) +
                         " equations per node (mixed DOF kinds, e.g. beam nodes or multipliers: use direct or gmres_ilu)");
    if (modes_.size() == 0) return;
    if (modes_.rows() != static_cast<Eigen::Index>(n))
      throw InputError("gmres_amg: the near-null space has " + std::to_string(modes_.rows()) + " rows but the system has " +
                         std::to_string(n));
    for (Eigen::Index i = 0; i < modes_.rows(); ++i)
      if (modes_.row(i).isZero(0.0))
        throw InputError("gmres_amg: unknown " + std::to_string(i) + " is zero in every near-null-space mode (a DOF " +
                           "the rigid-body modes do not describe, e.g. a beam rotation or a multiplier: use direct or gmres_ilu)");
  }

  // `reusable`: AMG keeps its prolongators for ReuseTpetraPreconditioner.
  RCP<OP> make_preconditioner(const RCP<Matrix>& mat, const RCP<const Map>& map, LinearSolveStats& stats, bool reusable) const {
    stats.preconditioner_built = true;
    if (settings_.type == LinearSolverType::gmres_ilu) {
      using RowMatrix = Tpetra::RowMatrix<SC, LO, GO, NO>;
      Teuchos::ParameterList p;
      RCP<Ifpack2::Preconditioner<SC, LO, GO, NO>> prec;
      if (comm_->getSize() == 1) {
        prec = Ifpack2::Factory::create<RowMatrix>("RILUK", mat);
        p.set("fact: iluk level-of-fill", settings_.ilu_fill);
      } else {
        prec = Ifpack2::Factory::create<RowMatrix>("SCHWARZ", mat);
        p.set("schwarz: inner preconditioner name", std::string("RILUK"));
        p.set("schwarz: overlap level", 1);
        Teuchos::ParameterList inner;
        inner.set("fact: iluk level-of-fill", settings_.ilu_fill);
        p.set("schwarz: inner preconditioner parameters", inner);
      }
      prec->setParameters(p);
      prec->initialize();
      prec->compute();
      return prec;
    }
    if (settings_.type == LinearSolverType::gmres_amg || settings_.type == LinearSolverType::gmres_amg_block) {
      Teuchos::ParameterList p;
      p.set("verbosity", std::string(settings_.verbosity > 0 ? "low" : "none"));
      p.set("multigrid algorithm", std::string("sa"));
      p.set("number of equations", settings_.amg_equations_per_node);
      p.set("coarse: max size", 1000);
      if (reusable) p.set("reuse: type", std::string("RP"));
      // Symmetric Gauss-Seidel smoothing, for the scalar Laplace problems of the
      // fibers and for elasticity alike. MueLu's default Chebyshev smoother
      // relies on a power-iteration estimate of the largest eigenvalue of
      // D^-1 A (10 iterations); where that misses the few large, element-local
      // eigenvalues (quadratic tets from gmsh's Delaunay mesher with aspect
      // ratio up to ~12; the stretched anisotropic HGO wall) the smoother
      // amplifies those modes and GMRES stagnates (straight-healthy tet10
      // fibers: 3e-6 after 5000 iterations, issue 5; Case 1 artery at 85 mmHg:
      // 714 GMRES iterations over 6 Newton iterations with Chebyshev, 422 with
      // Gauss-Seidel, bench_solver). Gauss-Seidel needs no spectral estimate and
      // converges for any SPD matrix; a forward and a backward sweep keep the
      // V-cycle symmetric. (In parallel, Ifpack2 applies it per rank: hybrid
      // Gauss-Seidel/Jacobi.)
      p.set("smoother: type", std::string("RELAXATION"));
      Teuchos::ParameterList& sp = p.sublist("smoother: params");
      sp.set("relaxation: type", std::string("Symmetric Gauss-Seidel"));
      sp.set("relaxation: sweeps", 1);
      if (!settings_.amg_parameters.empty()) {
        // The user's MueLu list (e.g. "aggregation: drop tol", "smoother: type") over ours.
        try {
          Teuchos::updateParametersFromXmlFileAndBroadcast(settings_.amg_parameters, Teuchos::Ptr<Teuchos::ParameterList>(&p), *comm_);
        } catch (const std::exception& e) {
          throw InputError("linear.amg_parameters: " + settings_.amg_parameters + " is not a MueLu XML parameter list: " + e.what());
        }
      }
      check_near_null_space(static_cast<GO>(map->getGlobalNumElements()));
      if (modes_.size() > 0) {
        RCP<MV> ns = rcp(new MV(map, static_cast<std::size_t>(modes_.cols())));
        for (LO i = 0; i < static_cast<LO>(map->getNodeNumElements()); ++i)
          for (Eigen::Index c = 0; c < modes_.cols(); ++c)
            ns->replaceLocalValue(i, static_cast<std::size_t>(c), modes_(map->getGlobalElement(i), c));
        p.sublist("user data").set("Nullspace", ns);
      }
      const int eq = settings_.amg_equations_per_node;
      const std::size_t local = map->getNodeNumElements();
      // Every rank decides alike (the node map's constructor is collective): coordinates only
      // when each rank's rows are whole nodes.
      const int whole = local % static_cast<std::size_t>(eq) == 0 && (local == 0 || map->getGlobalElement(0) % eq == 0);
      int all_whole = whole;
      Teuchos::reduceAll<int, int>(*comm_, Teuchos::REDUCE_MIN, 1, &whole, &all_whole);
      if (coordinates_.rows() * eq == static_cast<Eigen::Index>(map->getGlobalNumElements()) && all_whole) {
        // The node map: this rank's rows in blocks of eq (MueLu aggregates such blocks).
        RCP<const Map> nodes = rcp(new Map(static_cast<GO>(coordinates_.rows()), local / static_cast<std::size_t>(eq), 0, comm_));
        RCP<MV> xyz = rcp(new MV(nodes, static_cast<std::size_t>(coordinates_.cols())));
        for (LO i = 0; i < static_cast<LO>(nodes->getNodeNumElements()); ++i)
          for (Eigen::Index c = 0; c < coordinates_.cols(); ++c)
            xyz->replaceLocalValue(i, static_cast<std::size_t>(c), coordinates_(nodes->getGlobalElement(i), c));
        p.sublist("user data").set("Coordinates", xyz);
      }
      RCP<OP> op = mat;
      RCP<MueLu::TpetraOperator<SC, LO, GO, NO>> prec = MueLu::CreateTpetraPreconditioner(op, p);
      stats.amg_levels = prec->GetHierarchy()->GetNumLevels();
      return prec;
    }
    throw std::invalid_argument("unknown Krylov preconditioner for '" + linear_solver_name(settings_.type) + "'");
  }

  LinearSolverSettings settings_;
  RCP<const Teuchos::Comm<int>> comm_;
  // "direct": UMFPACK on rank 0 (keeps its symbolic analysis while the pattern stays).
  std::unique_ptr<LinearSolver> direct_ = make_umfpack_solver();
  // gmres_ilu and gmres_amg on one rank: the matrix and the preconditioner (RILUK, or
  // the MueLu hierarchy with its prolongators) kept while the pattern stays.
  KeptMatrix kept_;
  RCP<OP> kept_prec_;
  // gmres_amg_block: block 1's range, the split, its AMG (with its matrix and pattern) and block 2's LU.
  std::int64_t block_begin_ = 0, block_end_ = 0;
  BlockSplit split_;
  KeptMatrix block_;
  std::vector<double> amg_values_;  // block 1's AMG matrix values (scratch, kept for its capacity)
  RCP<MueLu::TpetraOperator<SC, LO, GO, NO>> block_amg_;
  RCP<const Map> block_map_;  // block 1's map (its AMG's)
  double block_amg_seconds_ = 0.0;  // the last set-up of block 1's AMG
  double block_lu_seconds_ = 0.0;   // and of block 2's LU
  UmfpackFactor block_lu_{false};  // no iterative refinement: GMRES corrects the block solve
  UmfpackFactor whole_lu_{false};  // gmres_lu's factors (likewise unrefined)
  Eigen::MatrixXd modes_;
  Eigen::MatrixXd coordinates_;       // set_node_coordinates
  double requested_tolerance_ = 0.0;  // set_relative_tolerance
  LagPolicy lag_;
};

}  // namespace

void initialize_parallel() { ensure_initialized(); }

std::unique_ptr<LinearSolver> make_trilinos_solver(const LinearSolverSettings& settings) {
  return std::make_unique<TrilinosSolver>(settings);
}

}  // namespace stentsim::solver
