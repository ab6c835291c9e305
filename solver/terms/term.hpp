#pragma once
// The one interface every physical term implements (DESIGN.md §2): solids,
// surface loads, springs, beams, joints and contact pairs add their residual
// and tangent over their own DOFs, and manage their own history. They meet
// only in the assembly.
//
// Conventions
// - Residual R = f_int - f_ext; Newton solves K du = -R with K = dR/du.
// - The global vector `u` holds every DOF. Additive DOFs (displacements,
//   Hermite tangents) are read from it directly. Rotational DOFs are updated
//   multiplicatively by the term that owns them: their entries in `du` are
//   rotation-vector increments (spatial/left convention, Lambda <- exp(S(dtheta)) Lambda,
//   stated again in the owning term) and `u` carries no meaning there.
// - MPI: every rank holds the whole `u`; each rank assembles the elements of
//   its partition (state.rank, state.ranks) and the assembler sums them.
#include <Eigen/Core>

#include "solver/terms/history_archive.hpp"

#include <span>
#include <string>

namespace stentsim::solver {

using GlobalDof = long long;

/// Where a term reads the current configuration and load level.
struct SystemState {
  const Eigen::VectorXd& u;   // all DOFs (additive ones meaningful)
  double time = 0.0;          // pseudo-time at the end of the current step
  double dt = 0.0;            // size of the current step
  int rank = 0, ranks = 1;    // this process's element partition
  /// Does element `e` (of `n`) belong to this rank? Contiguous blocks.
  bool owns(std::size_t e, std::size_t n) const {
    const std::size_t begin = n * static_cast<std::size_t>(rank) / static_cast<std::size_t>(ranks);
    const std::size_t end = n * static_cast<std::size_t>(rank + 1) / static_cast<std::size_t>(ranks);
    return e >= begin && e < end;
  }
};

class ConcurrentAssembler;

/// Receives element contributions; the global assembly sums them.
class Assembler {
 public:
  virtual ~Assembler() = default;
  /// Adds `residual` (size n) and `tangent` (n x n, row = equation, column =
  /// DOF) at the global DOFs `dofs`. A negative DOF index is a fixed DOF and
  /// its row and column are dropped.
  virtual void add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& residual,
                   const Eigen::Ref<const Eigen::MatrixXd>& tangent) = 0;
  /// Adds a residual only (for terms evaluated without tangent, e.g. reactions).
  virtual bool wants_tangent() const { return true; }
  /// Sinks for a threaded element loop, or null: this assembler takes blocks from one thread.
  virtual ConcurrentAssembler* concurrent() { return nullptr; }
};

/// Element blocks from several threads at once (threads.hpp, colouring.hpp). Each
/// thread adds through its own lane; blocks added at the same time through
/// different lanes share no row (the term colours its elements so). `order` is
/// the block's place in a sequence that does not depend on the threads: what a
/// lane holds back (entries outside the matrix pattern) joins the assembly in
/// that order at merge(), so the result is the same for any thread count.
class ConcurrentAssembler {
 public:
  virtual ~ConcurrentAssembler() = default;
  /// Thread `thread`'s sink (0 <= thread < the loop's thread count) for the block numbered `order`.
  virtual Assembler& lane(int thread, std::size_t order) = 0;
  /// After the loop, in one thread.
  virtual void merge() = 0;
  /// A threaded loop needs the matrix pattern of its blocks laid (entries outside it
  /// wait in memory until merge()): a term assembles serially, through the
  /// Assembler itself, until a finished tangent assembly has laid its pattern.
  /// laid(term) says that term's serial tangent blocks were all added; the pattern
  /// counts as laid once that assembly is finished.
  virtual bool pattern_laid(const void* term) const = 0;
  virtual void laid(const void* term) = 0;
};

class Term {
 public:
  virtual ~Term() = default;
  virtual std::string name() const = 0;

  /// Adds R and dR/du at `state` (and the term's trial internal state).
  virtual void assemble(const SystemState& state, Assembler& out) = 0;

  /// Called before every attempt of a load step, at the last converged state
  /// (so also after a rollback), before the step's first assembly: a term that
  /// keeps per-step data, such as a contact search, refreshes it here once per
  /// step instead of once per residual evaluation.
  virtual void begin_step(const SystemState& state) {}

  /// Multiplicative DOFs: set the trial state to (accepted iterate) composed
  /// with the increment `du` (global vector). May be called several times per
  /// iteration (line search); each call starts from the accepted iterate.
  virtual void trial(const Eigen::VectorXd& du) {}
  /// The last trial becomes the accepted iterate.
  virtual void accept() {}
  /// Points whose active state (contact) the last accept() changed on this rank: Newton's
  /// residual-floor test needs a settled active set (newton.hpp).
  virtual int accepted_changes() const { return 0; }
  /// Why this term cannot accept the converged state `state` (empty: it can).
  /// Some converged states are spurious: a loaded surface turned inside out
  /// balances its pressure as well as a real one does (face_orientation.hpp).
  /// Asked before commit() on every rank with the same u; a reason cuts the step
  /// like a failed iteration (DESIGN.md §7).
  virtual std::string rejects(const SystemState& state) const { return {}; }
  /// The load step converged: history and reference states move forward.
  virtual void commit() {}
  /// The load step is cut: go back to the last committed state.
  virtual void rollback() {}

  /// Restart (issue 6): write the committed history (the state after the last
  /// commit(): multiplicative DOFs, per-Gauss-point internal variables) into
  /// `out` under keys beginning with `prefix`, one flat array per field
  /// (history_archive.hpp gives the layout). A term whose state is fully in
  /// the global vector u writes nothing. `has_history()` must be true when the
  /// term keeps state between steps, so a solver can refuse to checkpoint a
  /// term that cannot save it.
  virtual bool has_history() const { return false; }
  virtual void save_history(HistoryArchive& out, const std::string& prefix) const {}
  /// Restores what save_history wrote; trial and accepted states become the committed one.
  virtual void load_history(const HistoryArchive& in, const std::string& prefix) {}
};

}  // namespace stentsim::solver
