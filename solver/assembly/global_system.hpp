#pragma once
// Global assembly: receives element contributions (Assembler), applies nodal
// frames and Dirichlet constraints on the fly and builds K (CSR) and R.
//   - rows of fixed DOFs become identity rows; their residual is kept as the
//     reaction (reactions()).
//   - columns of fixed DOFs move to the right-hand side with the prescribed
//     increment: rhs = -(R + K_fc du_c).
// The sparsity pattern is kept between assemblies and grows when a term adds
// a new coupling (contact).
#include <Eigen/Core>

#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include "solver/assembly/constraints.hpp"
#include "solver/linalg/csr_matrix.hpp"
#include "solver/terms/term.hpp"

namespace stentsim::solver {

class GlobalSystem : public Assembler, private ConcurrentAssembler {
 public:
  explicit GlobalSystem(const Constraints& constraints);

  /// Start an assembly. `prescribed` holds the increments of fixed DOFs
  /// (local coordinates) to eliminate; `with_tangent` false assembles R only.
  void begin(const Eigen::VectorXd& prescribed, bool with_tangent = true);
  void add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& residual,
           const Eigen::Ref<const Eigen::MatrixXd>& tangent) override;
  bool wants_tangent() const override { return with_tangent_; }
  /// Threaded element loops add through lanes (ConcurrentAssembler): one per thread
  /// of assembly_threads(), made on the first call.
  ConcurrentAssembler* concurrent() override;
  /// This rank among `ranks`: residuals are summed over ranks in finish(),
  /// the identity on fixed rows comes from rank 0 only.
  void set_parallel(int rank, int ranks) { rank_ = rank, ranks_ = ranks; }
  /// Merge new couplings into the pattern and put the identity on fixed rows.
  void finish();

  /// Residual in local coordinates, all DOFs (fixed ones hold reactions).
  const Eigen::VectorXd& residual() const { return residual_; }
  /// Norm of the residual over free DOFs.
  double free_residual_norm() const;
  /// Size of the forces in balance: the norm over free DOFs of m_d = Σ_c |r_c,d|, the
  /// magnitudes of every contribution c (element, contact point, load) to DOF d. At
  /// equilibrium the residual cancels them; |R| / |m| says how far from complete that is.
  /// Assembled with the tangent only (Newton judges accepted states, which always have one;
  /// the line search's residual-only trials skip it); zero after a residual-only assembly.
  double force_magnitude_norm() const;
  /// m itself (local coordinates, all DOFs; summed over ranks).
  const Eigen::VectorXd& force_magnitudes() const { return magnitude_; }
  /// Right-hand side of K du = rhs: -(R + K_fc du_c) at free DOFs, du_c at fixed ones.
  Eigen::VectorXd rhs() const;
  const CsrMatrix& matrix() const { return matrix_; }

 private:
  void insert(GlobalDof row, GlobalDof col, double value);
  // What one thread needs to scatter a block: rotated copies for nodal frames and
  // the block's columns, (DOF, local index), free and fixed. Grows, never shrinks:
  // no per-element allocation.
  struct Scratch {
    Eigen::VectorXd r;
    Eigen::MatrixXd k;
    std::vector<std::pair<GlobalDof, Eigen::Index>> free_cols, fixed_cols;
  };
  // Adds a block; `hold(row, col, value)` takes entries outside the pattern.
  template <class Hold>
  void scatter(Scratch& scratch, std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& residual,
               const Eigen::Ref<const Eigen::MatrixXd>& tangent, Hold&& hold);
  // A thread's sink in a threaded loop: entries outside the pattern wait, tagged
  // with their block's order, for merge().
  class Lane : public Assembler {
   public:
    explicit Lane(GlobalSystem& system) : system_(&system) {}
    void add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& residual,
             const Eigen::Ref<const Eigen::MatrixXd>& tangent) override;
    bool wants_tangent() const override { return system_->with_tangent_; }
    GlobalSystem* system_;
    std::size_t order = 0;
    Scratch scratch;
    std::vector<std::tuple<std::size_t, GlobalDof, GlobalDof, double>> held;
  };
  Assembler& lane(int thread, std::size_t order) override;
  void merge() override;
  bool pattern_laid(const void* term) const override;
  void laid(const void* term) override { laying_.push_back(term); }
  std::vector<Lane> lanes_;
  std::vector<const void*> laying_, laid_;  // terms whose pattern this assembly lays; has laid

  const Constraints& constraints_;
  Eigen::VectorXd residual_, correction_, prescribed_, magnitude_;
  CsrMatrix matrix_;
  std::vector<std::tuple<GlobalDof, GlobalDof, double>> pending_;  // entries outside the pattern
  /// Merges pending_'s repeated (row, column) entries once it holds more than
  /// `compact_at_`: overlapping element blocks that grow the pattern together (contact
  /// node blocks: ~6 adds per new entry) would otherwise hold every add until finish().
  void compact_pending();
  std::size_t compact_at_ = std::size_t{1} << 22;
  bool with_tangent_ = true;
  int rank_ = 0, ranks_ = 1;
  Scratch scratch_;  // add()'s
};

}  // namespace stentsim::solver
