#include "solver/contact/contact_surface.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <map>

#include "common/error.hpp"
#include "solver/terms/element_failure.hpp"

namespace stentsim::solver::contact {
namespace {

Mat3 cross_matrix(const Vec3& a) {
  Mat3 s;
  s << 0, -a(2), a(1), a(2), 0, -a(0), -a(1), a(0), 0;
  return s;
}

/// Tangents x,ξ1 and x,ξ2 of face f at (ξ1, ξ2).
std::pair<Vec3, Vec3> tangents(const SurfaceFace& f, const FaceShape& s, const std::vector<Vec3>& x) {
  Vec3 t1 = Vec3::Zero(), t2 = Vec3::Zero();
  for (int k = 0; k < f.count; ++k) {
    t1 += s.dn[k][0] * x[static_cast<std::size_t>(f.node[k])];
    t2 += s.dn[k][1] * x[static_cast<std::size_t>(f.node[k])];
  }
  return {t1, t2};
}

/// Reverses a face's orientation (its normal) keeping VTK's node order rules.
void reverse(SurfaceFace& f) {
  auto n = f.node;
  if (f.kind == FaceKind::quad4) f.node = {n[0], n[3], n[2], n[1], 0, 0};
  else if (f.kind == FaceKind::tri3) f.node = {n[0], n[2], n[1], 0, 0, 0};
  else f.node = {n[0], n[2], n[1], n[5], n[4], n[3]};
}

}  // namespace

ContactSurface::ContactSurface(std::string name, const SolidBody& body, const std::vector<fem::Face>& faces)
    : name_(std::move(name)), body_(body) {
  if (faces.empty()) throw InputError(fmt::format("contact surface '{}': no faces", name_));
  std::map<std::int64_t, int> local;
  const MeshData& m = body.mesh();
  for (const auto& f : faces) {
    SurfaceFace s;
    s.kind = face_kind(f.type);
    s.count = f.count;
    s.cell = f.cell;
    for (int k = 0; k < f.count; ++k) {
      auto [it, fresh] = local.try_emplace(f.nodes[static_cast<std::size_t>(k)], static_cast<int>(body_node_.size()));
      if (fresh) body_node_.push_back(static_cast<std::size_t>(f.nodes[static_cast<std::size_t>(k)]));
      s.node[static_cast<std::size_t>(k)] = it->second;
    }
    faces_.push_back(s);
  }
  x_.resize(body_node_.size());
  for (std::size_t i = 0; i < body_node_.size(); ++i) x_[i] = m.points[body_node_[i]];
  // Orientation: out of the bounded cell (its centroid lies behind the face).
  for (auto& f : faces_) {
    const auto c = face_center(f.kind);
    const auto [t1, t2] = tangents(f, face_shape(f.kind, c[0], c[1]), x_);
    Vec3 fc = Vec3::Zero(), cc = Vec3::Zero();
    for (int k = 0; k < f.count; ++k) fc += x_[static_cast<std::size_t>(f.node[k])] / f.count;
    const auto conn = m.cell(f.cell);
    for (auto n : conn) cc += m.points[static_cast<std::size_t>(n)] / static_cast<double>(conn.size());
    if (t1.cross(t2).dot(fc - cc) < 0) {
      reverse(f);
      ++reversed_;
    }
  }
  node_faces_.resize(body_node_.size());
  for (std::size_t f = 0; f < faces_.size(); ++f)
    for (int k = 0; k < faces_[f].count; ++k) node_faces_[static_cast<std::size_t>(faces_[f].node[k])].push_back(static_cast<int>(f));
  n_.resize(body_node_.size());
  update(Eigen::VectorXd::Zero(body.first_dof() + body.num_dofs()));
}

void ContactSurface::update(const Eigen::VectorXd& u) {
  for (std::size_t i = 0; i < body_node_.size(); ++i) x_[i] = body_.position(u, body_node_[i]);
  for (std::size_t i = 0; i < body_node_.size(); ++i) {
    Vec3 a = Vec3::Zero();
    for (int fi : node_faces_[i]) {
      const SurfaceFace& f = faces_[static_cast<std::size_t>(fi)];
      const int k = static_cast<int>(std::find(f.node.begin(), f.node.begin() + f.count, static_cast<int>(i)) - f.node.begin());
      const auto xi = face_node_xi(f.kind, k);
      const auto [t1, t2] = tangents(f, face_shape(f.kind, xi[0], xi[1]), x_);
      a += t1.cross(t2);
    }
    const double r = a.norm();
    if (!(r > 0.0))
      throw ElementFailure(fmt::format("contact surface '{}': the nodal normal of node {} of body '{}' is undefined (its faces are "
                                     "degenerate or fold onto each other)", name_, body_node_[i], body_.name()));
    n_[i] = a / r;
  }
  dn_valid_.assign(body_node_.size(), 0);
  if (dn_.size() != body_node_.size()) dn_.resize(body_node_.size());
}

const NormalDerivatives& ContactSurface::normal_derivatives(int local, bool hessians) const {
  const std::size_t i = static_cast<std::size_t>(local);
  // dn_valid_: 0 nothing, 1 the Jacobian, 2 the Jacobian and the Hessians. Threads of one
  // element loop may ask for the same node: the first computes under the node's lock, the
  // others see its flag. Adding the Hessians later leaves the patch and the Jacobian that
  // other threads may be reading untouched.
  const char need = hessians ? 2 : 1;
  std::atomic_ref<char> valid(dn_valid_[i]);
  if (valid.load(std::memory_order_acquire) >= need) return dn_[i];
  const std::lock_guard<std::mutex> lock(locks_.of(i));
  const char have = valid.load(std::memory_order_relaxed);
  if (have >= need) return dn_[i];
  NormalDerivatives t;
  compute_normal_derivatives(local, hessians, t);
  if (have == 0) dn_[i] = std::move(t);
  else dn_[i].hessian = std::move(t.hessian);
  valid.store(need, std::memory_order_release);
  return dn_[i];
}

void ContactSurface::compute_normal_derivatives(int local, bool hessians, NormalDerivatives& d) const {
  const std::size_t i = static_cast<std::size_t>(local);
  d.patch.clear();
  for (int fi : node_faces_[i]) {
    const SurfaceFace& f = faces_[static_cast<std::size_t>(fi)];
    for (int k = 0; k < f.count; ++k) d.patch.push_back(f.node[k]);
  }
  std::sort(d.patch.begin(), d.patch.end());
  d.patch.erase(std::unique(d.patch.begin(), d.patch.end()), d.patch.end());
  const int m = static_cast<int>(d.patch.size());
  auto slot = [&](int node) { return static_cast<int>(std::lower_bound(d.patch.begin(), d.patch.end(), node) - d.patch.begin()); };
  Eigen::MatrixXd ja = Eigen::MatrixXd::Zero(3, 3 * m);
  std::array<Eigen::MatrixXd, 3> ha;
  if (hessians)
    for (auto& h : ha) h = Eigen::MatrixXd::Zero(3 * m, 3 * m);
  Vec3 a = Vec3::Zero();
  for (int fi : node_faces_[i]) {
    const SurfaceFace& f = faces_[static_cast<std::size_t>(fi)];
    const int ki = static_cast<int>(std::find(f.node.begin(), f.node.begin() + f.count, local) - f.node.begin());
    const auto xi = face_node_xi(f.kind, ki);
    const FaceShape s = face_shape(f.kind, xi[0], xi[1]);
    const auto [t1, t2] = tangents(f, s, x_);
    a += t1.cross(t2);
    const Mat3 s1 = cross_matrix(t1), s2 = cross_matrix(t2);
    for (int k = 0; k < f.count; ++k) {
      const int ck = 3 * slot(f.node[k]);
      ja.block<3, 3>(0, ck) += -s.dn[k][0] * s2 + s.dn[k][1] * s1;
      for (int l = 0; l < f.count && hessians; ++l) {
        const int cl = 3 * slot(f.node[l]);
        const double w = s.dn[k][0] * s.dn[l][1] - s.dn[l][0] * s.dn[k][1];
        if (w == 0.0) continue;
        // ε_bpq w: the (p, q) entry of block (k, l) of Hessian b.
        for (int b = 0; b < 3; ++b) {
          const int p = (b + 1) % 3, q = (b + 2) % 3;
          ha[b](ck + p, cl + q) += w;
          ha[b](ck + q, cl + p) -= w;
        }
      }
    }
  }
  const double rho = a.norm();
  const Vec3 n = a / rho;
  const Mat3 P = Mat3::Identity() - n * n.transpose();
  d.jacobian = P / rho * ja;
  if (!hessians) return;
  for (int c = 0; c < 3; ++c) {
    Mat3 hn;
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) hn(p, q) = -(n(p) * P(c, q) + n(q) * P(c, p) + n(c) * P(p, q)) / (rho * rho);
    d.hessian[c] = ja.transpose() * hn * ja;
    for (int b = 0; b < 3; ++b)
      if (P(c, b) != 0.0) d.hessian[c] += (P(c, b) / rho) * ha[b];
  }
}

double ContactSurface::min_edge_length() const {
  double h = std::numeric_limits<double>::infinity();
  for (const auto& f : faces_) {
    const int corners = f.kind == FaceKind::quad4 ? 4 : 3;
    for (int k = 0; k < corners; ++k)
      h = std::min(h, (x_[static_cast<std::size_t>(f.node[k])] - x_[static_cast<std::size_t>(f.node[(k + 1) % corners])]).norm());
  }
  return h;
}

}  // namespace stentsim::solver::contact
