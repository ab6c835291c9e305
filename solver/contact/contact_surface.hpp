#pragma once
// A solid body's contact surface: the selected boundary faces (quad4, tri3,
// tri6), their nodes, the current node positions and the field of averaged
// nodal normals with its first and second derivatives.
//
// Nodal normal (Steinbrecher et al. 2022, beam-to-surface contact; as 4C's
// averaged nodal normals): a_I = Σ_{f ∋ I} x,ξ1 × x,ξ2 of face f at node I's
// parametric point (area-weighted), n_I = a_I / |a_I|. a_I is bilinear in the
// positions of I's patch (the nodes of the faces around I), so
//   ∂a/∂x_k = −N_k,1 [x,ξ2]× + N_k,2 [x,ξ1]×,
//   ∂²a_b/∂x_kp ∂x_lq = ε_bpq (N_k,1 N_l,2 − N_l,1 N_k,2),
// and with ρ = |a|, P = I − n nᵀ:
//   ∂n/∂a = P/ρ,  ∂²n_c/∂a_i∂a_j = −(n_i P_cj + n_j P_ci + n_c P_ij)/ρ².
// Faces are oriented so that their right-hand normal points out of the cell
// they bound, whatever the node order of the file (a face whose normal points
// into its cell is reversed), so normals point out of the solid.
#include <Eigen/Core>

#include <array>
#include <mutex>
#include <string>
#include <vector>

#include "solver/contact/face_shapes.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/terms/solid_body.hpp"

namespace stentsim::solver::contact {

struct SurfaceFace {
  FaceKind kind = FaceKind::quad4;
  std::array<int, 6> node{};  // surface-local node indices, VTK order, outward
  int count = 0;
  std::size_t cell = 0;       // the volume cell of the body it bounds
};

/// A face as linear triangles of its surface-local nodes, outward like the face: a quad4 as
/// two, a tri6 as four through its mid-side nodes (VTK order), for measures that need flat
/// pieces (distances, plane cuts).
inline std::vector<std::array<int, 3>> linear_triangles(const SurfaceFace& f) {
  const auto& n = f.node;
  if (f.kind == FaceKind::quad4) return {{n[0], n[1], n[2]}, {n[0], n[2], n[3]}};
  if (f.kind == FaceKind::tri3) return {{n[0], n[1], n[2]}};
  return {{n[0], n[3], n[5]}, {n[3], n[1], n[4]}, {n[5], n[4], n[2]}, {n[3], n[4], n[5]}};
}

/// d n_I / d(positions of its patch): the patch's surface-local nodes, the
/// 3 x 3m Jacobian (columns node-major) and the three 3m x 3m Hessians.
struct NormalDerivatives {
  std::vector<int> patch;
  Eigen::MatrixXd jacobian;
  std::array<Eigen::MatrixXd, 3> hessian;
};

class ContactSurface {
 public:
  /// `faces` index the body's nodes (fem::boundary_faces, filtered by a selection).
  ContactSurface(std::string name, const SolidBody& body, const std::vector<fem::Face>& faces);

  const std::string& name() const { return name_; }
  const SolidBody& body() const { return body_; }
  const std::vector<SurfaceFace>& faces() const { return faces_; }
  std::size_t num_nodes() const { return body_node_.size(); }
  std::size_t body_node(int local) const { return body_node_[static_cast<std::size_t>(local)]; }
  GlobalDof dof(int local, int component) const { return body_.dof(body_node(local), component); }
  /// Faces that hold node `local`.
  const std::vector<int>& node_faces(int local) const { return node_faces_[static_cast<std::size_t>(local)]; }
  /// Number of faces whose normal the constructor reversed (file node order inward).
  int reversed_faces() const { return reversed_; }

  /// Current positions and unit nodal normals at u (derivatives are recomputed on demand).
  void update(const Eigen::VectorXd& u);
  const Vec3& x(int local) const { return x_[static_cast<std::size_t>(local)]; }
  const Vec3& normal(int local) const { return n_[static_cast<std::size_t>(local)]; }
  /// Derivatives of normal(local) at the last update (computed once per update, cached);
  /// the Hessians only when asked for (the gap-variation form of contact needs none).
  /// Safe to call from several threads at once (a threaded element loop).
  const NormalDerivatives& normal_derivatives(int local, bool hessians = true) const;
  /// Reference positions (u = 0).
  Vec3 reference(int local) const { return body_.mesh().points[body_node(local)]; }
  /// Smallest edge length of the faces at the last update (for the element-size warning).
  double min_edge_length() const;

 private:
  std::string name_;
  const SolidBody& body_;
  std::vector<SurfaceFace> faces_;
  std::vector<std::size_t> body_node_;
  std::vector<std::vector<int>> node_faces_;
  std::vector<Vec3> x_, n_;
  void compute_normal_derivatives(int local, bool hessians, NormalDerivatives& d) const;
  mutable std::vector<NormalDerivatives> dn_;
  mutable std::vector<char> dn_valid_;  // read and set through std::atomic_ref
  // Striped locks for the first computation of a node's derivatives; a copy of the
  // surface gets locks of its own.
  struct Locks {
    Locks() = default;
    Locks(const Locks&) {}
    Locks& operator=(const Locks&) { return *this; }
    std::mutex& of(std::size_t node) const { return m[node % m.size()]; }
    mutable std::array<std::mutex, 32> m;
  };
  Locks locks_;
  int reversed_ = 0;
};

}  // namespace stentsim::solver::contact
