#include "solver/contact/surface_to_surface_pair.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/contact/owned_flags.hpp"
#include "solver/beams/element_reference.hpp"
#include "solver/contact/face_bounds.hpp"
#include "solver/contact/face_search.hpp"
#include "solver/terms/element_failure.hpp"

namespace stentsim::solver::contact {
namespace {

/// Reference points and weights on a face: n × n Gauss–Legendre on quad4; on
/// triangles the collapsed (Duffy) n × n rule ξ1 = u (1 − v), ξ2 = v.
std::vector<std::pair<std::array<double, 2>, double>> face_rule(FaceKind kind, int n) {
  std::vector<double> x, w;
  beams::gauss_legendre(n, x, w);
  std::vector<std::pair<std::array<double, 2>, double>> r;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      if (kind == FaceKind::quad4) {
        r.push_back({{x[static_cast<std::size_t>(a)], x[static_cast<std::size_t>(b)]}, w[static_cast<std::size_t>(a)] * w[static_cast<std::size_t>(b)]});
      } else {
        const double u = 0.5 * (1 + x[static_cast<std::size_t>(a)]), v = 0.5 * (1 + x[static_cast<std::size_t>(b)]);
        r.push_back({{u * (1 - v), v}, 0.25 * w[static_cast<std::size_t>(a)] * w[static_cast<std::size_t>(b)] * (1 - v)});
      }
    }
  return r;
}

/// Residual-only collector (evaluate's force totals).
class ResidualCollector : public Assembler {
 public:
  void add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& r, const Eigen::Ref<const Eigen::MatrixXd>&) override {
    for (std::size_t i = 0; i < dofs.size(); ++i)
      if (dofs[i] >= 0) values[dofs[i]] += r(static_cast<Eigen::Index>(i));
  }
  bool wants_tangent() const override { return false; }
  std::map<GlobalDof, double> values;
};

// Intermediate variables of a node's weighted gap: 3-vectors, keyed by kind and surface-local node.
enum VarKind { slave_x = 0, slave_n = 1, master_x = 2 };
struct VarKey {
  int kind, node;
  bool operator==(const VarKey&) const = default;
};

}  // namespace

SurfaceToSurfacePair::SurfaceToSurfacePair(std::string name, std::unique_ptr<ContactSurface> slave,
                                           std::unique_ptr<ContactSurface> master, SurfaceToSurfaceSettings settings)
    : name_(std::move(name)), slave_(std::move(slave)), master_(std::move(master)), settings_(settings) {
  if (!(settings_.law.epsilon > 0.0)) throw InputError(fmt::format("contact pair '{}': the penalty must be positive", name_));
  if (!(settings_.search_margin > 0.0)) throw InputError(fmt::format("contact pair '{}': the search margin must be positive", name_));
  if (settings_.gauss_points < 1) throw InputError(fmt::format("contact pair '{}': at least one Gauss point per direction", name_));
  area_.assign(slave_->num_nodes(), 0.0);
  for (const SurfaceFace& f : slave_->faces()) {
    std::vector<GaussPoint> g;
    for (const auto& [xi, w] : face_rule(f.kind, settings_.gauss_points)) {
      GaussPoint p;
      p.shape = face_shape(f.kind, xi[0], xi[1]);
      Vec3 t1 = Vec3::Zero(), t2 = Vec3::Zero();
      for (int k = 0; k < f.count; ++k) {
        t1 += p.shape.dn[k][0] * slave_->reference(f.node[k]);
        t2 += p.shape.dn[k][1] * slave_->reference(f.node[k]);
      }
      p.gauss_weight = w;
      p.weight = w * t1.cross(t2).norm();
      for (int k = 0; k < f.count; ++k) area_[static_cast<std::size_t>(f.node[k])] += p.shape.n[k] * p.weight;
      g.push_back(p);
    }
    gauss_.push_back(std::move(g));
  }
  active_.resize(slave_->num_nodes());
  reserved_.assign(slave_->num_nodes(), {});
}

void SurfaceToSurfacePair::search(const ContactSurface& slave, const ContactSurface& master, Candidates& out) const {
  FaceSearch grid;
  grid.build(master, settings_.search_margin);
  const double grow = std::max(settings_.law.active_limit(), 0.0);
  out.assign(slave.faces().size(), {});
  for (std::size_t f = 0; f < slave.faces().size(); ++f) {
    const SurfaceFace& face = slave.faces()[f];
    Eigen::AlignedBox3d box;
    for (int k = 0; k < face.count; ++k) box.extend(slave.x(face.node[k]));
    box.min().array() -= grow;
    box.max().array() += grow;
    grid.query(box.min(), box.max(), out[f]);
  }
}

void SurfaceToSurfacePair::refresh_search() {
  search(*slave_, *master_, candidates_);
  ++searches_;
  searched_slave_.resize(slave_->num_nodes());
  for (std::size_t i = 0; i < slave_->num_nodes(); ++i) searched_slave_[i] = slave_->x(static_cast<int>(i));
  searched_master_.resize(master_->num_nodes());
  for (std::size_t i = 0; i < master_->num_nodes(); ++i) searched_master_[i] = master_->x(static_cast<int>(i));
}

bool SurfaceToSurfacePair::moved_too_far() const {
  const double limit2 = 0.25 * settings_.search_margin * settings_.search_margin;
  for (std::size_t i = 0; i < slave_->num_nodes(); ++i)
    if ((slave_->x(static_cast<int>(i)) - searched_slave_[i]).squaredNorm() > limit2) return true;
  for (std::size_t i = 0; i < master_->num_nodes(); ++i)
    if ((master_->x(static_cast<int>(i)) - searched_master_[i]).squaredNorm() > limit2) return true;
  return false;
}

void SurfaceToSurfacePair::begin_step(const SystemState& state) {
  slave_->update(state.u);
  master_->update(state.u);
  refresh_search();
  active_.begin_step();
}

void SurfaceToSurfacePair::point_gaps(const ContactSurface& slave, const ContactSurface& master, const Candidates& cand,
                                      const std::vector<Eigen::AlignedBox3d>& master_boxes, int face, std::vector<PointGap>& out) const {
  const SurfaceFace& f = slave.faces()[static_cast<std::size_t>(face)];
  const int nk = f.count;
  const auto& rule = gauss_[static_cast<std::size_t>(face)];
  out.assign(rule.size(), {});
  for (std::size_t q = 0; q < rule.size(); ++q) {
    const FaceShape& sh = rule[q].shape;
    Vec3 p = Vec3::Zero(), m = Vec3::Zero();
    for (int k = 0; k < nk; ++k) p += sh.n[k] * slave.x(f.node[k]), m += sh.n[k] * slave.normal(f.node[k]);
    const Vec3 d = m.normalized();
    PointGap& pg = out[q];
    const double reach = settings_.search_margin;
    for (int mf : cand[static_cast<std::size_t>(face)]) {
      if (!segment_meets_box(p, d, -reach, reach, master_boxes[static_cast<std::size_t>(mf)])) continue;
      const DirectionProjection pr = project_along_direction(master, mf, p, d, settings_.inside_tolerance);
      if (pr.kind != ProjectionKind::inside || pr.face_normal.dot(d) >= 0.0 || std::abs(pr.alpha) > settings_.search_margin) continue;
      if (pg.master < 0 || std::abs(pr.alpha) < std::abs(pg.gap)) pg.master = mf, pg.projection = pr, pg.gap = pr.alpha;
    }
  }
}

void SurfaceToSurfacePair::point_gap_derivatives(const ContactSurface& slave, const ContactSurface& master, int face,
                                                 int derivatives, std::vector<PointGap>& points) const {
  const SurfaceFace& f = slave.faces()[static_cast<std::size_t>(face)];
  const int nk = f.count;
  const auto& rule = gauss_[static_cast<std::size_t>(face)];
  GapDerivatives gd;
  for (std::size_t q = 0; q < rule.size(); ++q) {
    PointGap& pg = points[q];
    if (pg.master < 0) continue;
    const FaceShape& sh = rule[q].shape;
    Vec3 m = Vec3::Zero();
    for (int k = 0; k < nk; ++k) m += sh.n[k] * slave.normal(f.node[k]);
    const double rho = m.norm();
    const Vec3 d = m / rho;
    const int nm = master.faces()[static_cast<std::size_t>(pg.master)].count;
    direction_gap_derivatives(master, pg.master, pg.projection, d, derivatives > 1, gd);
    // v = (p, d, y_l) -> w = (x_k, n_k, y_l): p = Σ N_k x_k, d = m/|m|, m = Σ N_k n_k.
    const int nw = 6 * nk + 3 * nm;
    const Mat3 P = Mat3::Identity() - d * d.transpose();
    const Vec3 a = gd.grad.segment<3>(3);
    pg.grad.setZero(nw);
    for (int k = 0; k < nk; ++k) {
      pg.grad.segment<3>(3 * k) = sh.n[k] * gd.grad.head<3>();
      pg.grad.segment<3>(3 * nk + 3 * k) = sh.n[k] / rho * (P * a);
    }
    pg.grad.tail(3 * nm) = gd.grad.tail(3 * nm);
    if (derivatives < 2) continue;
    // pg.hess = Vᵀ gd.hess V with V = ∂v/∂w block-structured: p → x_k by N_k I, d → n_k by
    // (N_k/ρ) P, y_l by I. Formed block by block from the three v-blocks' products with P
    // (Hpd P, P Hdd P, P Hdy), scaled by the shape values, instead of as dense products.
    const Eigen::MatrixXd& Hv = gd.hess;
    const Mat3 Hpp = Hv.block<3, 3>(0, 0), HpdP = Hv.block<3, 3>(0, 3) * P, PHddP = P * Hv.block<3, 3>(3, 3) * P;
    const Eigen::MatrixXd Hpy = Hv.block(0, 6, 3, 3 * nm), PHdy = P * Hv.block(3, 6, 3, 3 * nm);
    pg.hess.resize(nw, nw);
    for (int k = 0; k < nk; ++k) {
      const double nk_ = sh.n[k];
      for (int l = 0; l < nk; ++l) {
        const double nn = nk_ * sh.n[l];
        pg.hess.block<3, 3>(3 * k, 3 * l) = nn * Hpp;
        pg.hess.block<3, 3>(3 * k, 3 * nk + 3 * l) = (nn / rho) * HpdP;
        pg.hess.block<3, 3>(3 * nk + 3 * l, 3 * k) = (nn / rho) * HpdP.transpose();
        pg.hess.block<3, 3>(3 * nk + 3 * k, 3 * nk + 3 * l) = (nn / (rho * rho)) * PHddP;
      }
      pg.hess.block(3 * k, 6 * nk, 3, 3 * nm) = nk_ * Hpy;
      pg.hess.block(6 * nk, 3 * k, 3 * nm, 3) = nk_ * Hpy.transpose();
      pg.hess.block(3 * nk + 3 * k, 6 * nk, 3, 3 * nm) = (nk_ / rho) * PHdy;
      pg.hess.block(6 * nk, 3 * nk + 3 * k, 3 * nm, 3) = (nk_ / rho) * PHdy.transpose();
    }
    pg.hess.bottomRightCorner(3 * nm, 3 * nm) = Hv.bottomRightCorner(3 * nm, 3 * nm);
    // Σ_c α_{d_c} ∂²d_c/∂m∂m = −[d (Pa)ᵀ + (Pa) dᵀ + (a·d) P] / ρ².
    const Vec3 Pa = P * a;
    const Mat3 S = -(d * Pa.transpose() + Pa * d.transpose() + a.dot(d) * P) / (rho * rho);
    for (int k = 0; k < nk; ++k)
      for (int l = 0; l < nk; ++l) pg.hess.block<3, 3>(3 * nk + 3 * k, 3 * nk + 3 * l) += sh.n[k] * sh.n[l] * S;
  }
}

SurfaceToSurfacePair::NodeResult SurfaceToSurfacePair::assemble_node(const ContactSurface& slave, const ContactSurface& master, int j,
                                                                     const std::vector<std::vector<PointGap>>& gaps, bool tangent,
                                                                     Assembler* out) const {
  NodeResult res;
  const double A = area_[static_cast<std::size_t>(j)];
  auto local_index = [&](const SurfaceFace& f) {
    return static_cast<int>(std::find(f.node.begin(), f.node.begin() + f.count, j) - f.node.begin());
  };
  for (int fi : slave.node_faces(j)) {
    const SurfaceFace& f = slave.faces()[static_cast<std::size_t>(fi)];
    const int kj = local_index(f);
    const auto& rule = gauss_[static_cast<std::size_t>(fi)];
    for (std::size_t q = 0; q < rule.size(); ++q) {
      const PointGap& pg = gaps[static_cast<std::size_t>(fi)][q];
      if (pg.master < 0) continue;
      const double c = rule[q].shape.n[kj] * rule[q].weight;
      res.weighted_gap += c * pg.gap;
      res.covered += c;
    }
  }
  double phi, d1, d2;
  settings_.law.eval(res.weighted_gap / A, phi, d1, d2);
  res.active = res.covered > 0.0 && res.weighted_gap / A < settings_.law.active_limit();
  if (!res.active || out == nullptr) return res;

  // ∂g̃_j (G) and ∂²g̃_j (H) in the intermediate variables, 3-vectors keyed by VarKey.
  std::vector<VarKey> keys;
  auto slot = [&](int kind, int node) {
    const VarKey key{kind, node};
    auto it = std::find(keys.begin(), keys.end(), key);
    if (it != keys.end()) return static_cast<int>(it - keys.begin());
    keys.push_back(key);
    return static_cast<int>(keys.size()) - 1;
  };
  // Face-local variable blocks -> slots, per (face, hit master face).
  auto block_slots = [&](const SurfaceFace& f, int master_face) {
    const SurfaceFace& mf = master.faces()[static_cast<std::size_t>(master_face)];
    std::vector<int> s;
    for (int k = 0; k < f.count; ++k) s.push_back(slot(slave_x, f.node[k]));
    for (int k = 0; k < f.count; ++k) s.push_back(slot(slave_n, f.node[k]));
    for (int l = 0; l < mf.count; ++l) s.push_back(slot(master_x, mf.node[l]));
    return s;
  };
  Eigen::VectorXd g_group;
  Eigen::MatrixXd h_group;
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::VectorXd G;
    Eigen::MatrixXd H;
    if (pass == 1) {
      const auto n = static_cast<Eigen::Index>(3 * keys.size());
      G.setZero(n);
      if (tangent) H.setZero(n, n);
    }
    // The points of one slave face that hit the same master face share their variables:
    // their weighted derivatives are summed in the face-local layout first (contiguous,
    // vectorised) and moved into the node's slots once per such group.
    for (int fi : slave.node_faces(j)) {
      const SurfaceFace& f = slave.faces()[static_cast<std::size_t>(fi)];
      const int kj = local_index(f);
      const auto& rule = gauss_[static_cast<std::size_t>(fi)];
      const auto& face_gaps = gaps[static_cast<std::size_t>(fi)];
      for (std::size_t first = 0; first < rule.size(); ++first) {
        const int m = face_gaps[first].master;
        if (m < 0) continue;
        bool seen = false;  // a group is taken at its first point
        for (std::size_t q = 0; q < first && !seen; ++q) seen = face_gaps[q].master == m;
        if (seen) continue;
        const std::vector<int> s = block_slots(f, m);
        if (pass == 0) continue;
        g_group.setZero(face_gaps[first].grad.size());
        if (tangent) h_group.setZero(g_group.size(), g_group.size());
        for (std::size_t q = first; q < rule.size(); ++q) {
          const PointGap& pg = face_gaps[q];
          if (pg.master != m) continue;
          const double c = rule[q].shape.n[kj] * rule[q].weight;
          g_group += c * pg.grad;
          if (tangent) h_group += c * pg.hess;
        }
        for (std::size_t a = 0; a < s.size(); ++a) {
          G.segment<3>(3 * s[a]) += g_group.segment<3>(3 * static_cast<Eigen::Index>(a));
          if (!tangent) continue;
          for (std::size_t b = 0; b < s.size(); ++b)
            H.block<3, 3>(3 * s[a], 3 * s[b]) += h_group.block<3, 3>(3 * static_cast<Eigen::Index>(a), 3 * static_cast<Eigen::Index>(b));
        }
      }
    }
    if (pass == 0) continue;

    // Intermediate variables -> DOFs: slave x_i (identity), slave n_i (its patch, ∂n_i/∂x), master x_l (identity).
    std::vector<int> snodes, mnodes;
    for (const VarKey& k : keys) {
      if (k.kind == slave_x) snodes.push_back(k.node);
      else if (k.kind == master_x) mnodes.push_back(k.node);
      else {
        const auto& nd = slave.normal_derivatives(k.node);
        snodes.insert(snodes.end(), nd.patch.begin(), nd.patch.end());
      }
    }
    auto unique_sorted = [](std::vector<int>& v) {
      std::sort(v.begin(), v.end());
      v.erase(std::unique(v.begin(), v.end()), v.end());
    };
    unique_sorted(snodes);
    unique_sorted(mnodes);
    auto sslot = [&](int n) { return 3 * static_cast<int>(std::lower_bound(snodes.begin(), snodes.end(), n) - snodes.begin()); };
    auto mslot = [&](int n) {
      return 3 * static_cast<int>(snodes.size() + static_cast<std::size_t>(std::lower_bound(mnodes.begin(), mnodes.end(), n) - mnodes.begin()));
    };
    const int ndof = 3 * static_cast<int>(snodes.size() + mnodes.size());
    const int nvar = 3 * static_cast<int>(keys.size());
    // T = ∂(variables)/∂(DOFs) by its 3 × 3 blocks, never formed: per variable the
    // (column slot, block) pairs — identity for the slave and master positions, the
    // nodal normal's Jacobian over its patch. Applied as Tᵀ G and Tᵀ (H T); T is
    // mostly identity blocks, so this is several times cheaper than dense products.
    // Positions map to one column slot by identity (ident[v], no products); normals by their blocks.
    std::vector<std::vector<std::pair<int, Mat3>>> map(keys.size());
    std::vector<int> ident(keys.size(), -1);
    for (std::size_t v = 0; v < keys.size(); ++v) {
      const VarKey& k = keys[v];
      if (k.kind == slave_x) ident[v] = sslot(k.node);
      else if (k.kind == master_x) ident[v] = mslot(k.node);
      else {
        const auto& nd = slave.normal_derivatives(k.node);
        for (std::size_t m = 0; m < nd.patch.size(); ++m)
          map[v].emplace_back(sslot(nd.patch[m]), nd.jacobian.block<3, 3>(0, 3 * static_cast<Eigen::Index>(m)));
      }
    }
    Eigen::VectorXd gD = Eigen::VectorXd::Zero(ndof);
    for (std::size_t v = 0; v < keys.size(); ++v) {
      const auto vi = 3 * static_cast<Eigen::Index>(v);
      if (ident[v] >= 0) gD.segment<3>(ident[v]) += G.segment<3>(vi);
      for (const auto& [col, J] : map[v]) gD.segment<3>(col) += J.transpose() * G.segment<3>(vi);
    }
    std::vector<GlobalDof> dofs;
    for (int n : snodes)
      for (int c = 0; c < 3; ++c) dofs.push_back(slave.dof(n, c));
    for (int n : mnodes)
      for (int c = 0; c < 3; ++c) dofs.push_back(master.dof(n, c));
    const Eigen::VectorXd R = d1 * gD;
    Eigen::MatrixXd K;
    if (tangent) {
      Eigen::MatrixXd HT = Eigen::MatrixXd::Zero(nvar, ndof);
      for (std::size_t v = 0; v < keys.size(); ++v) {
        const auto vi = 3 * static_cast<Eigen::Index>(v);
        if (ident[v] >= 0) HT.middleCols<3>(ident[v]) += H.middleCols<3>(vi);
        for (const auto& [col, J] : map[v]) HT.middleCols<3>(col).noalias() += H.middleCols<3>(vi) * J;
      }
      Eigen::MatrixXd HD = Eigen::MatrixXd::Zero(ndof, ndof);
      for (std::size_t v = 0; v < keys.size(); ++v) {
        const auto vi = 3 * static_cast<Eigen::Index>(v);
        if (ident[v] >= 0) HD.middleRows<3>(ident[v]) += HT.middleRows<3>(vi);
        for (const auto& [row, J] : map[v]) HD.middleRows<3>(row).noalias() += J.transpose() * HT.middleRows<3>(vi);
      }
      for (std::size_t v = 0; v < keys.size(); ++v) {
        if (keys[v].kind != slave_n) continue;
        const auto& nd = slave.normal_derivatives(keys[v].node);
        std::vector<int> s(nd.patch.size());
        for (std::size_t m = 0; m < nd.patch.size(); ++m) s[m] = sslot(nd.patch[m]);
        for (int c = 0; c < 3; ++c) {
          const double gc = G[3 * static_cast<Eigen::Index>(v) + c];
          if (gc == 0.0) continue;
          for (std::size_t a = 0; a < s.size(); ++a)
            for (std::size_t b = 0; b < s.size(); ++b)
              HD.block<3, 3>(s[a], s[b]) += gc * nd.hessian[static_cast<std::size_t>(c)].block<3, 3>(3 * static_cast<Eigen::Index>(a), 3 * static_cast<Eigen::Index>(b));
        }
      }
      K.noalias() = (d2 / A) * gD * gD.transpose();
      K += d1 * HD;
    }
    out->add(dofs, R, K);
  }
  return res;
}

std::vector<GlobalDof> SurfaceToSurfacePair::block_dofs(int j, const std::vector<int>& master_faces) const {
  std::vector<int> snodes, mnodes;
  for (int fi : slave_->node_faces(j)) {
    const SurfaceFace& f = slave_->faces()[static_cast<std::size_t>(fi)];
    for (int k = 0; k < f.count; ++k) {
      const auto& nd = slave_->normal_derivatives(f.node[k]);
      snodes.insert(snodes.end(), nd.patch.begin(), nd.patch.end());
    }
  }
  for (int mf : master_faces) {
    const SurfaceFace& m = master_->faces()[static_cast<std::size_t>(mf)];
    mnodes.insert(mnodes.end(), m.node.begin(), m.node.begin() + m.count);
  }
  std::sort(snodes.begin(), snodes.end());
  snodes.erase(std::unique(snodes.begin(), snodes.end()), snodes.end());
  std::sort(mnodes.begin(), mnodes.end());
  mnodes.erase(std::unique(mnodes.begin(), mnodes.end()), mnodes.end());
  std::vector<GlobalDof> dofs;
  if (mnodes.empty()) return dofs;
  for (int n : snodes)
    for (int c = 0; c < 3; ++c) dofs.push_back(slave_->dof(n, c));
  for (int n : mnodes)
    for (int c = 0; c < 3; ++c) dofs.push_back(master_->dof(n, c));
  return dofs;
}

void SurfaceToSurfacePair::assemble(const SystemState& state, Assembler& out) {
  slave_->update(state.u);
  master_->update(state.u);
  if (searched_slave_.empty() || moved_too_far()) {
    log::debug("contact '{}': a node moved more than half the search margin ({:g} mm): searching again", name_,
               settings_.search_margin);
    refresh_search();
  }
  const bool tangent = out.wants_tangent();
  rank_ = state.rank, ranks_ = state.ranks;
  const std::size_t ns = slave_->num_nodes();
  // Gauss points of the faces around the owned slave nodes: first their gaps,
  // which decide each node's activity, then the derivatives only on the faces
  // around an active node (most of the surface is out of contact most of the
  // time, and the Hessians are the expensive part).
  std::vector<std::vector<PointGap>> gaps(slave_->faces().size());
  const std::vector<Eigen::AlignedBox3d> boxes = face_boxes(*master_);
  std::vector<char> done(slave_->faces().size(), 0);
  for (std::size_t j = 0; j < ns; ++j) {
    if (!state.owns(j, ns)) continue;
    for (int fi : slave_->node_faces(static_cast<int>(j))) {
      if (done[static_cast<std::size_t>(fi)]) continue;
      point_gaps(*slave_, *master_, candidates_, boxes, fi, gaps[static_cast<std::size_t>(fi)]);
      done[static_cast<std::size_t>(fi)] = 1;
    }
  }
  for (std::size_t j = 0; j < ns; ++j) {
    if (!state.owns(j, ns) || !assemble_node(*slave_, *master_, static_cast<int>(j), gaps, false, nullptr).active) continue;
    for (int fi : slave_->node_faces(static_cast<int>(j))) {
      if (done[static_cast<std::size_t>(fi)] == 2) continue;
      point_gap_derivatives(*slave_, *master_, fi, tangent ? 2 : 1, gaps[static_cast<std::size_t>(fi)]);
      done[static_cast<std::size_t>(fi)] = 2;
    }
  }
  for (std::size_t j = 0; j < ns; ++j) {
    if (!state.owns(j, ns)) continue;
    const NodeResult r = assemble_node(*slave_, *master_, static_cast<int>(j), gaps, tangent, &out);
    if (tangent) {
      const int changes = active_.evaluate(j, r.active);
      if (changes > settings_.max_flips)
        throw ElementFailure(fmt::format("contact '{}': slave node {} of body '{}' switched in and out of contact {} times in this "
                                         "step (active-set chattering; max_flips = {})", name_, slave_->body_node(static_cast<int>(j)),
                                         slave_->body().name(), changes, settings_.max_flips));
    }
    if (tangent) {
      // Reserve node j's block over the master faces its Gauss points hit within the search
      // margin, active or not yet, so that contact usually starts inside the pattern the
      // linear solver has analysed. Only these: on the paper-scale benchmark (bench_contact)
      // this pair's entries would be 18.0 M over every candidate face of the search and
      // 10.6 M with the hit faces' neighbours too, against 4.1 M over the hit faces, and a
      // direct solver's fill grows with them. A point that slides onto a new face grows the
      // pattern (the linear solver analyses it again; GlobalSystem logs it).
      // The global pattern only grows: a block is reserved again only when a hit face is
      // new, over the union with the faces reserved before.
      std::vector<int> hits;
      for (int fi : slave_->node_faces(static_cast<int>(j)))
        for (const PointGap& pg : gaps[static_cast<std::size_t>(fi)])
          if (pg.master >= 0) hits.push_back(pg.master);
      std::sort(hits.begin(), hits.end());
      hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
      std::vector<int>& last = reserved_[j];
      if (std::includes(last.begin(), last.end(), hits.begin(), hits.end())) continue;
      std::vector<int> merged;
      std::set_union(last.begin(), last.end(), hits.begin(), hits.end(), std::back_inserter(merged));
      const std::vector<GlobalDof> dofs = block_dofs(static_cast<int>(j), merged);
      const auto n = static_cast<Eigen::Index>(dofs.size());
      if (n > 0) out.add(dofs, Eigen::VectorXd::Zero(n), Eigen::MatrixXd::Zero(n, n));
      last.swap(merged);
    }
  }
}

SurfaceContactState SurfaceToSurfacePair::evaluate(const Eigen::VectorXd& u) const {
  ContactSurface slave = *slave_, master = *master_;
  slave.update(u);
  master.update(u);
  Candidates cand;
  search(slave, master, cand);
  std::vector<std::vector<PointGap>> gaps(slave.faces().size());
  const std::vector<Eigen::AlignedBox3d> boxes = face_boxes(master);
  SurfaceContactState st;
  for (std::size_t f = 0; f < slave.faces().size(); ++f) {
    point_gaps(slave, master, cand, boxes, static_cast<int>(f), gaps[f]);
    point_gap_derivatives(slave, master, static_cast<int>(f), 1, gaps[f]);
    const SurfaceFace& face = slave.faces()[f];
    for (std::size_t q = 0; q < gaps[f].size(); ++q) {
      SurfaceContactPoint p;
      p.slave_face = static_cast<int>(f), p.gauss_point = static_cast<int>(q);
      for (int k = 0; k < face.count; ++k) p.position += gauss_[f][q].shape.n[k] * slave.x(face.node[k]);
      p.master_face = gaps[f][q].master;
      p.master_xi = gaps[f][q].projection.xi;
      p.gap = gaps[f][q].gap;
      st.points.push_back(p);
    }
  }
  // Current nodal areas a_j = ∫ N_j da.
  std::vector<double> current(slave.num_nodes(), 0.0);
  for (std::size_t f = 0; f < slave.faces().size(); ++f) {
    const SurfaceFace& face = slave.faces()[f];
    for (const GaussPoint& g : gauss_[f]) {
      Vec3 t1 = Vec3::Zero(), t2 = Vec3::Zero();
      for (int k = 0; k < face.count; ++k) t1 += g.shape.dn[k][0] * slave.x(face.node[k]), t2 += g.shape.dn[k][1] * slave.x(face.node[k]);
      const double da = g.gauss_weight * t1.cross(t2).norm();
      for (int k = 0; k < face.count; ++k) current[static_cast<std::size_t>(face.node[k])] += g.shape.n[k] * da;
    }
  }
  ResidualCollector rc;
  for (std::size_t j = 0; j < slave.num_nodes(); ++j) {
    const NodeResult r = assemble_node(slave, master, static_cast<int>(j), gaps, false, &rc);
    SurfaceContactNode n;
    n.node = static_cast<int>(j);
    n.body_node = slave.body_node(n.node);
    n.position = slave.x(n.node);
    n.area = area_[j];
    n.current_area = current[j];
    n.covered_area = r.covered;
    n.weighted_gap = r.weighted_gap;
    n.mean_gap = r.weighted_gap / n.area;
    n.active = r.active;
    if (r.active) {
      double phi, d1, d2;
      settings_.law.eval(n.mean_gap, phi, d1, d2);
      n.pressure = -d1;
      n.current_pressure = n.pressure * n.area / n.current_area;
    }
    st.nodes.push_back(n);
  }
  std::map<GlobalDof, std::pair<int, int>> owner;  // DOF -> (0 slave / 1 master, component)
  for (std::size_t i = 0; i < slave.num_nodes(); ++i)
    for (int c = 0; c < 3; ++c) owner[slave.dof(static_cast<int>(i), c)] = {0, c};
  for (std::size_t i = 0; i < master.num_nodes(); ++i)
    for (int c = 0; c < 3; ++c) owner.try_emplace(master.dof(static_cast<int>(i), c), std::pair<int, int>{1, c});
  for (const auto& [dof, r] : rc.values) {
    const auto it = owner.find(dof);
    if (it == owner.end()) continue;
    (it->second.first == 0 ? st.force_on_slave : st.force_on_master)[it->second.second] -= r;
  }
  return st;
}

void SurfaceToSurfacePair::commit() {
  active_.commit(1, rank_, ranks_);  // one flag per slave node
}

void SurfaceToSurfacePair::save_history(HistoryArchive& out, const std::string& prefix) const {
  active_.save(out, prefix + "active");
}

void SurfaceToSurfacePair::load_history(const HistoryArchive& in, const std::string& prefix) {
  active_.load(in, prefix + "active");
}

}  // namespace stentsim::solver::contact
