#pragma once
// Beam-to-solid-surface penalty contact (paper 2.5; DESIGN.md §5 Contact):
//   Π = Σ_elements Σ_gp w_gp φ(g(s_gp)),  g = d − R  (form `potential`; the
//   default `gap_variation` takes the virtual work along n̂, see BeamContactForm),
// frictionless, d the signed distance of the beam centerline point r(s) to the
// solid surface measured along the field of averaged nodal normals
// (normal_projection.hpp), R the beam radius, φ the penalty law
// (penalty_law.hpp; ε in N/mm²), w_gp = Gauss weight × ds/dξ of the reference
// centerline (6 Gauss points per element by default, the paper's count). The
// centerline comes from the Hermite (or Lagrange) positions and tangents; the
// rotations do not enter. The residual and the consistent tangent cover the
// beam's centerline DOFs, the face's nodes and, through the nodal normals,
// the nodes of the face's normal patch:
//   potential:      R = Tᵀ (φ' ∂d/∂v),  K = Tᵀ (φ'' ∂d ∂dᵀ + φ' ∂²d) T + Σ_k φ' ∂d/∂n_k · ∂²n_k,
//   gap_variation:  R_beam = φ' Bᵀ n̂, R_face = −φ' Nᵀ n̂,  K = ∂R/∂v · T (∂n̂, ∂N through ξ(v)),
// v = (beam centerline vectors, face node positions x_k, nodal normals n_k),
// T = ∂v/∂(DOFs).
//
// Search: once per step (begin_step) each beam element collects the faces
// whose boxes lie within the search margin of its Gauss points (face_search.hpp),
// and searches again when a Gauss point or a surface node moved more than half
// the margin since. A pair whose point projects onto a face within reach (the
// margin) reserves its matrix pattern while still apart (zeros), so contact
// usually starts inside the analysed pattern; the pattern only grows.
// Projection failures: a Gauss point that finds no face it projects inside is
// out of contact — unless it was in contact in the last converged state: then
// the trial state is a failed iteration (ElementFailure) and the step is cut,
// never a silent loss of a contact point. Active-set chattering (a point that
// flips in and out more than `max_flips` times between the accepted Newton
// iterates of one step, active_set.hpp) also fails the
// iteration. MPI: every rank searches all elements and assembles the beam
// elements of its fixed partition (SystemState::owns).
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "solver/beams/beam_term.hpp"
#include "solver/contact/active_set.hpp"
#include "solver/contact/contact_surface.hpp"
#include "solver/contact/face_search.hpp"
#include "solver/contact/normal_projection.hpp"
#include "solver/contact/penalty_law.hpp"

namespace stentsim::solver::contact {

/// How the penalty enters the weak form.
/// - gap_variation (default, as 4C's): δW = Σ w φ'(g) n̂·(δr − Σ_k N_k δx_k), the force along
///   the interpolated averaged normal n̂(ξ); continuous where the faceted surface has a kink
///   (on either side), equal and opposite on beam and surface; non-symmetric tangent.
/// - potential: δW = δΠ, Π = Σ w φ(g); symmetric tangent, the force along ∂g/∂r, which is
///   normal to the level sets of g, hence to the facets: it turns by the facet angle at a kink.
enum class BeamContactForm { gap_variation, potential };

struct BeamToSurfaceSettings {
  BeamContactForm form = BeamContactForm::gap_variation;
  PenaltyLaw law;
  int gauss_points = 6;
  double radius = 0.0;         // beam radius R [mm]
  double search_margin = 0.0;  // [mm]; 0: 2 R
  int max_flips = 8;           // active-set changes of one point within one step
  double inside_tolerance = 1e-9;
};

/// State of one contact Gauss point (output, checks).
struct BeamContactPoint {
  std::size_t element = 0;
  int gauss_point = 0;
  double xi = 0.0;               // beam element parameter
  Vec3 position = Vec3::Zero();  // centerline point r(s)
  bool projected = false;        // found a face it projects inside (within reach)
  bool deep = false;             // projects inside a face, but deeper than the reach (a centerline far through the surface)
  int face = -1;
  double gap = 0.0;              // g = d − R [mm] (meaningful when projected)
  Vec3 line_load = Vec3::Zero(); // contact force per length on the beam [N/mm]
  double weight = 0.0;           // w_gp [mm]
  bool active = false;
};

class BeamToSurfacePair : public Term {
 public:
  BeamToSurfacePair(std::string name, const beams::BeamTerm& beam, std::unique_ptr<ContactSurface> surface,
                    BeamToSurfaceSettings settings);

  std::string name() const override { return name_; }
  void begin_step(const SystemState& state) override;
  void assemble(const SystemState& state, Assembler& out) override;
  /// Every rank evaluated its own elements only: the flags are gathered so that every rank
  /// (and rank 0's checkpoint) holds all of them.
  void commit() override;
  void accept() override {
    const ActiveSet::Changes c = active_.accept();
    accepted_changes_ = c.entered + c.left;
    ActiveSet::log_changes(name_, c);
  }
  int accepted_changes() const override { return accepted_changes_; }
  void rollback() override { active_.rollback(); }
  /// The active flags of the last converged state (the projection-failure rule needs them).
  bool has_history() const override { return true; }
  void save_history(HistoryArchive& out, const std::string& prefix) const override;
  void load_history(const HistoryArchive& in, const std::string& prefix) override;

  const beams::BeamTerm& beam() const { return beam_; }
  const ContactSurface& surface() const { return *surface_; }
  const BeamToSurfaceSettings& settings() const { return settings_; }
  /// Every Gauss point at u, all elements (every rank the same); searches afresh.
  std::vector<BeamContactPoint> evaluate(const Eigen::VectorXd& u) const;
  /// Times the search ran (begin_step or a point that moved past half the margin).
  long long searches() const { return searches_; }

 private:
  struct GaussPoint {
    double xi, weight;
    std::array<double, 4> B;  // centerline functions (tangent scaling included)
  };
  struct Candidates {
    std::vector<int> faces;
  };
  void search(const ContactSurface& surface, const Eigen::VectorXd& u, std::vector<Candidates>& out) const;
  std::array<Vec3, 4> centerline(const Eigen::VectorXd& u, std::size_t e) const;
  /// Where a point's projections put it: near a face (`face` ≥ 0, the inside projection of
  /// smallest |d| within reach), apart (inside a face but farther out than the reach), deep
  /// (inside a face but farther in than the reach), or nowhere (no projection inside a face;
  /// `unconverged` counts the points left nowhere for which some candidate's local Newton did not converge).
  enum class Reach { near, apart, deep, nowhere };
  NormalProjection project(const ContactSurface& surface, const std::vector<int>& faces, const Vec3& p, int& face, Reach& reach,
                           int* unconverged = nullptr, const std::vector<Eigen::AlignedBox3d>* boxes = nullptr) const;
  bool moved_too_far(const Eigen::VectorXd& u) const;
  // What beam elements add, kept by a chunk of the threaded loop until its turn to
  // scatter: blocks in the order the serial loop adds them, reused across assemblies.
  struct Block {
    std::vector<GlobalDof> dofs;
    Eigen::VectorXd r;
    Eigen::MatrixXd k;
  };
  /// Accumulated contributions of one (beam element, face) pair in the variables
  /// v' = (beam centerline vectors [3 nc], face node positions [3 nf], nodal normals [3 nf]).
  struct PairBlock {
    int face = -1;
    Eigen::VectorXd g;
    Eigen::MatrixXd k;
  };
  struct Chunk {
    std::vector<Block> blocks;
    std::size_t used = 0;
    int unconverged = 0;
    std::vector<std::pair<std::size_t, std::vector<int>>> reserved;  // (element, its reserved faces after this chunk)
    Block& next();
    // element_blocks' scratch, kept for the slot's next element.
    GapDerivatives gd;
    NormalFieldDerivatives nd;
    std::vector<PairBlock> pairs;
    std::vector<int> near, patch;
  };
  /// Element e's blocks (pairs with active points, then reserved patterns) into `out`.
  void element_blocks(const SystemState& state, std::size_t e, bool tangent, Chunk& out);
  std::vector<Chunk> chunks_;  // per slot of the threaded loop
  /// Search at u and remember the positions it was made at.
  void refresh_search(const Eigen::VectorXd& u);

  std::string name_;
  const beams::BeamTerm& beam_;
  std::unique_ptr<ContactSurface> surface_;
  BeamToSurfaceSettings settings_;
  double margin_ = 0.0;
  int nc_ = 4;  // centerline vectors per element
  std::vector<std::vector<GaussPoint>> gauss_;  // per element
  std::vector<Candidates> candidates_;           // per element, from the last search
  /// Per face, its box at the last search grown by the reach and the margin (what it may move
  /// before the next search): a point outside it cannot project onto the face within reach.
  std::vector<Eigen::AlignedBox3d> face_boxes_;
  std::vector<Vec3> searched_points_, searched_nodes_;
  std::vector<std::vector<int>> reserved_;  // per element, the faces whose pattern was reserved (sorted)
  ActiveSet active_;  // per Gauss point (element-major)
  int accepted_changes_ = 0;  // points the last accept() switched
  long long searches_ = 0;
  int unconverged_ = 0;  // points left nowhere with a failed projection, in the last tangent assembly
  int rank_ = 0, ranks_ = 1;  // partition of the last assembly
};

}  // namespace stentsim::solver::contact
