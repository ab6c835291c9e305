#pragma once
// Surface-to-surface penalty contact, balloon–artery (paper 2.5; DESIGN.md §5
// Contact): frictionless, mortar-type node-wise penalty regularization
// (Popp et al., mortar penalty contact; as 4C's weighted gaps) with
// element-based integration.
//
// Weighted gap of slave node j (slave = a ContactSurface, e.g. the balloon's
// outer face; master = another one, e.g. the endothelium):
//   g̃_j = ∫_slave N_j g dA,   A_j = ∫_slave N_j dA,
// both over the REFERENCE slave surface (dA = |X,1 × X,2| dξ), so A_j is a
// constant and p_j below is a force per reference area (a nominal pressure;
// `current_pressure` rescales it by A_j / a_j with the current nodal area a_j).
// g at a slave point x_s(ξ) = Σ N_k x_k is the distance along the slave's unit
// normal n̂_s = Σ N_k n_k / |Σ N_k n_k| (averaged nodal normals, contact_surface.hpp)
// to the master surface: x_m(η) = x_s + g n̂_s (direction_projection.hpp), so
// g < 0 is penetration. A point counts when its ray hits a candidate master face
// inside, from that face's outer side (n_m · n̂_s < 0), within |g| ≤ the search
// margin; of several, the nearest (smallest |g|). A point that hits none
// contributes nothing to g̃_j (it still belongs to A_j).
// Potential (one function of all DOFs, so the tangent is its Hessian):
//   Π = Σ_j A_j φ(ḡ_j),  ḡ_j = g̃_j / A_j,
// φ the penalty law (penalty_law.hpp, ε in N/mm³; unsmoothed φ = ε/2 ⟨−ḡ⟩², so
// Π = Σ_j (ε/2) ⟨−g̃_j⟩² / A_j), nodal pressure p_j = −φ'(ḡ_j) = ε ⟨−g̃_j / A_j⟩.
//   R = Σ_j φ'(ḡ_j) ∂g̃_j,   K = Σ_j [φ''(ḡ_j)/A_j ∂g̃_j ∂g̃_jᵀ + φ'(ḡ_j) ∂²g̃_j],
// over the active nodes (ḡ_j < the law's active limit). g̃_j depends on the
// slave face nodes, the slave nodal normals (hence their patches, through
// ContactSurface::normal_derivatives) and the master face nodes.
// Integration: n × n Gauss–Legendre points per slave quad4 (collapsed n × n
// on triangles), each projected on its own (element-based integration: the
// integrand's kinks at master edges are not resolved, hence a patch-test
// error that falls with n; see tests/solver/contact_surface_to_surface_test.cpp).
//
// Search: once per step (begin_step), each slave face collects the master faces
// whose boxes lie within the margin of its own box (face_search.hpp); the search
// is redone when a slave or master node moved more than half the margin since.
// A slave node reserves its matrix block over the master faces its Gauss points
// hit within the margin (before it is active), not over all the candidates.
// Active-set chattering (a node that flips more than `max_flips` times in one
// step, counted between accepted Newton iterates: active_set.hpp) fails the
// iteration (ElementFailure) so the step is cut.
// MPI: every rank searches everything and assembles the slave nodes of its
// fixed partition (SystemState::owns over slave nodes), computing the
// Gauss points of the faces around them.
#include <Eigen/Geometry>

#include <memory>
#include <string>
#include <vector>

#include "solver/contact/active_set.hpp"
#include "solver/contact/contact_surface.hpp"
#include "solver/contact/direction_projection.hpp"
#include "solver/contact/penalty_law.hpp"
#include "solver/terms/term.hpp"

namespace stentsim::solver::contact {

struct SurfaceToSurfaceSettings {
  PenaltyLaw law;               // ε in N/mm³ (paper: 5)
  int gauss_points = 4;         // per direction and slave face (4 × 4 on quad4)
  double search_margin = 0.0;   // [mm]; required > 0 (e.g. about a slave element size)
  int max_flips = 8;            // active-set changes of one node within one step
  double inside_tolerance = 1e-9;
};

/// One slave node (output, checks).
struct SurfaceContactNode {
  int node = 0;                  // slave surface-local index
  std::size_t body_node = 0;     // node of the slave body
  Vec3 position = Vec3::Zero();
  double area = 0.0;             // A_j [mm²], reference
  double current_area = 0.0;     // a_j = ∫ N_j da [mm²], current
  double covered_area = 0.0;     // ∫ N_j dA over the points that hit the master [mm²]
  double weighted_gap = 0.0;     // g̃_j [mm³]
  double mean_gap = 0.0;         // ḡ_j = g̃_j / A_j [mm]
  double pressure = 0.0;         // p_j = −φ'(ḡ_j) [MPa], per reference area
  double current_pressure = 0.0; // p_j A_j / a_j [MPa], per current area
  bool active = false;
};

/// One slave Gauss point (output, checks).
struct SurfaceContactPoint {
  int slave_face = 0, gauss_point = 0;
  Vec3 position = Vec3::Zero();
  int master_face = -1;          // -1: its ray hit no master face
  std::array<double, 2> master_xi{};
  double gap = 0.0;              // [mm]
};

struct SurfaceContactState {
  std::vector<SurfaceContactNode> nodes;
  std::vector<SurfaceContactPoint> points;
  Vec3 force_on_slave = Vec3::Zero();   // Σ over slave DOFs of −R [N]
  Vec3 force_on_master = Vec3::Zero();  // Σ over master DOFs of −R [N]
};

class SurfaceToSurfacePair : public Term {
 public:
  SurfaceToSurfacePair(std::string name, std::unique_ptr<ContactSurface> slave, std::unique_ptr<ContactSurface> master,
                       SurfaceToSurfaceSettings settings);

  std::string name() const override { return name_; }
  void begin_step(const SystemState& state) override;
  void assemble(const SystemState& state, Assembler& out) override;
  void commit() override;
  void accept() override {
    const ActiveSet::Changes c = active_.accept();
    accepted_changes_ = c.entered + c.left;
    ActiveSet::log_changes(name_, c);
  }
  int accepted_changes() const override { return accepted_changes_; }
  void rollback() override { active_.rollback(); }
  /// The nodal active flags of the last converged state (the chattering count starts from them).
  bool has_history() const override { return true; }
  void save_history(HistoryArchive& out, const std::string& prefix) const override;
  void load_history(const HistoryArchive& in, const std::string& prefix) override;

  const ContactSurface& slave() const { return *slave_; }
  const ContactSurface& master() const { return *master_; }
  const SurfaceToSurfaceSettings& settings() const { return settings_; }
  /// Reference nodal areas A_j of the slave nodes.
  const std::vector<double>& nodal_areas() const { return area_; }
  /// Every slave node and Gauss point at u, and the total forces (every rank the same); searches afresh.
  SurfaceContactState evaluate(const Eigen::VectorXd& u) const;
  /// Times the search ran (begin_step or a node that moved past half the margin).
  long long searches() const { return searches_; }

 private:
  struct GaussPoint {
    FaceShape shape;
    double gauss_weight = 0.0;  // on the reference face
    double weight = 0.0;        // Gauss weight × |X,1 × X,2|
  };
  /// The gap at one slave Gauss point and its derivatives in the face-local
  /// variables w = (slave face x_k [3 nk], slave nodal normals n_k [3 nk], master face x_l [3 nm]).
  struct PointGap {
    int master = -1;
    DirectionProjection projection;
    double gap = 0.0;
    Eigen::VectorXd grad;
    Eigen::MatrixXd hess;
  };
  using Candidates = std::vector<std::vector<int>>;  // master faces per slave face

  void search(const ContactSurface& slave, const ContactSurface& master, Candidates& out) const;
  void refresh_search();
  bool moved_too_far() const;
  /// Projects the Gauss points of slave face `face` (gap and hit master face
  /// only); point_gap_derivatives adds their derivatives (1: gradient, 2: and
  /// Hessian), which are needed only around active slave nodes.
  /// `master_boxes`: face_boxes(master), which cull the candidates a point's ray cannot hit.
  void point_gaps(const ContactSurface& slave, const ContactSurface& master, const Candidates& cand,
                  const std::vector<Eigen::AlignedBox3d>& master_boxes, int face, std::vector<PointGap>& out) const;
  void point_gap_derivatives(const ContactSurface& slave, const ContactSurface& master, int face, int derivatives,
                             std::vector<PointGap>& points) const;
  /// Adds node j's residual (and tangent) at the current surfaces to `out`; returns the weighted gap.
  struct NodeResult {
    double weighted_gap = 0.0, covered = 0.0;
    bool active = false;
  };
  NodeResult assemble_node(const ContactSurface& slave, const ContactSurface& master, int j,
                           const std::vector<std::vector<PointGap>>& gaps, bool tangent, Assembler* out) const;
  /// DOFs of node j's block against `master_faces` (pattern reservation).
  std::vector<GlobalDof> block_dofs(int j, const std::vector<int>& master_faces) const;

  std::string name_;
  std::unique_ptr<ContactSurface> slave_, master_;
  int rank_ = 0, ranks_ = 1;  // partition of the last assembly
  SurfaceToSurfaceSettings settings_;
  std::vector<std::vector<GaussPoint>> gauss_;  // per slave face
  std::vector<double> area_;                    // A_j per slave node
  Candidates candidates_;
  std::vector<Vec3> searched_slave_, searched_master_;
  Candidates reserved_;  // per slave node, the master faces its reserved blocks cover (sorted)
  ActiveSet active_;  // per slave node
  int accepted_changes_ = 0;  // nodes the last accept() switched
  long long searches_ = 0;
};

}  // namespace stentsim::solver::contact
