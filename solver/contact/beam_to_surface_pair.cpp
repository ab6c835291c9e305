#include "solver/contact/beam_to_surface_pair.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>
#include <cmath>
#include <map>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/assembly/threads.hpp"
#include "solver/contact/owned_flags.hpp"
#include "solver/terms/element_failure.hpp"

namespace stentsim::solver::contact {

BeamToSurfacePair::BeamToSurfacePair(std::string name, const beams::BeamTerm& beam, std::unique_ptr<ContactSurface> surface,
                                     BeamToSurfaceSettings settings)
    : name_(std::move(name)), beam_(beam), surface_(std::move(surface)), settings_(settings) {
  if (!(settings_.radius > 0.0)) throw InputError(fmt::format("contact pair '{}': the beam radius must be positive", name_));
  if (!(settings_.law.epsilon > 0.0)) throw InputError(fmt::format("contact pair '{}': the penalty must be positive", name_));
  margin_ = settings_.search_margin > 0.0 ? settings_.search_margin : 2.0 * settings_.radius;
  const auto& body = beam_.body();
  nc_ = body.interpolation == beams::BeamInterpolation::hermite3 ? 4 : 2;
  for (std::size_t e = 0; e < body.elements.size(); ++e) {
    const beams::ElementReference& r = beam_.reference(e);
    const beams::ElementReference c = beams::make_element_reference(r.kind, r.x0, r.q0, settings_.gauss_points);
    std::vector<GaussPoint> g;
    for (const auto& p : c.points) g.push_back({p.xi, p.weight_ds, p.B});
    gauss_.push_back(std::move(g));
  }
  const std::size_t points = body.elements.size() * static_cast<std::size_t>(settings_.gauss_points);
  active_.resize(points);
  reserved_.assign(body.elements.size(), {});
}

std::array<Vec3, 4> BeamToSurfacePair::centerline(const Eigen::VectorXd& u, std::size_t e) const {
  const std::vector<GlobalDof> d = beam_.element_dofs(e);
  const beams::ElementReference& r = beam_.reference(e);
  std::array<Vec3, 4> x{};
  for (int k = 0; k < nc_; ++k) {
    x[static_cast<std::size_t>(k)] = r.x0[static_cast<std::size_t>(k)];
    for (int c = 0; c < 3; ++c) {
      const GlobalDof g = d[static_cast<std::size_t>(3 * k + c)];
      if (g >= 0) x[static_cast<std::size_t>(k)][c] += u[g];
    }
  }
  return x;
}

void BeamToSurfacePair::search(const ContactSurface& surface, const Eigen::VectorXd& u, std::vector<Candidates>& out) const {
  FaceSearch grid;
  grid.build(surface, margin_);
  const double reach = settings_.radius + settings_.law.active_limit();
  out.assign(gauss_.size(), {});
  for (std::size_t e = 0; e < gauss_.size(); ++e) {
    const auto x = centerline(u, e);
    Eigen::AlignedBox3d box;
    for (const auto& g : gauss_[e]) {
      Vec3 p = Vec3::Zero();
      for (int k = 0; k < nc_; ++k) p += g.B[static_cast<std::size_t>(k)] * x[static_cast<std::size_t>(k)];
      box.extend(p);
    }
    box.min().array() -= reach;
    box.max().array() += reach;
    grid.query(box.min(), box.max(), out[e].faces);
  }
}

bool BeamToSurfacePair::moved_too_far(const Eigen::VectorXd& u) const {
  const double limit2 = 0.25 * margin_ * margin_;
  std::size_t k = 0;
  for (std::size_t e = 0; e < gauss_.size(); ++e) {
    const auto x = centerline(u, e);
    for (const auto& g : gauss_[e]) {
      Vec3 p = Vec3::Zero();
      for (int j = 0; j < nc_; ++j) p += g.B[static_cast<std::size_t>(j)] * x[static_cast<std::size_t>(j)];
      if ((p - searched_points_[k++]).squaredNorm() > limit2) return true;
    }
  }
  for (std::size_t i = 0; i < surface_->num_nodes(); ++i)
    if ((surface_->x(static_cast<int>(i)) - searched_nodes_[i]).squaredNorm() > limit2) return true;
  return false;
}

void BeamToSurfacePair::refresh_search(const Eigen::VectorXd& u) {
  search(*surface_, u, candidates_);
  const double grow = settings_.radius + settings_.law.active_limit() + 2.0 * margin_;
  face_boxes_.assign(surface_->faces().size(), Eigen::AlignedBox3d());
  for (std::size_t f = 0; f < face_boxes_.size(); ++f) {
    const SurfaceFace& face = surface_->faces()[f];
    for (int k = 0; k < face.count; ++k) face_boxes_[f].extend(surface_->x(face.node[k]));
    face_boxes_[f].min().array() -= grow;
    face_boxes_[f].max().array() += grow;
  }
  ++searches_;
  searched_points_.clear();
  for (std::size_t e = 0; e < gauss_.size(); ++e) {
    const auto x = centerline(u, e);
    for (const auto& g : gauss_[e]) {
      Vec3 p = Vec3::Zero();
      for (int k = 0; k < nc_; ++k) p += g.B[static_cast<std::size_t>(k)] * x[static_cast<std::size_t>(k)];
      searched_points_.push_back(p);
    }
  }
  searched_nodes_.assign(surface_->num_nodes(), Vec3::Zero());
  for (std::size_t i = 0; i < surface_->num_nodes(); ++i) searched_nodes_[i] = surface_->x(static_cast<int>(i));
}

void BeamToSurfacePair::begin_step(const SystemState& state) {
  surface_->update(state.u);
  refresh_search(state.u);
  active_.begin_step();
}

NormalProjection BeamToSurfacePair::project(const ContactSurface& surface, const std::vector<int>& faces, const Vec3& p,
                                            int& face, Reach& where, int* unconverged,
                                            const std::vector<Eigen::AlignedBox3d>* boxes) const {
  NormalProjection best;
  face = -1;
  where = Reach::nowhere;
  // Within reach: a point farther than the margin from the surface is apart whatever the face.
  const double reach = settings_.radius + settings_.law.active_limit() + margin_;
  bool apart = false, deep = false, failed = false;
  for (int f : faces) {
    // Outside the face's grown box: farther than the reach from it (apart from this face).
    if (boxes && !(*boxes)[static_cast<std::size_t>(f)].contains(p)) {
      apart = true;
      continue;
    }
    const NormalProjection pr = project_along_normals(surface, f, p, settings_.inside_tolerance);
    failed = failed || pr.kind == ProjectionKind::not_converged;
    if (pr.kind != ProjectionKind::inside) continue;
    if (pr.distance > reach) { apart = true; continue; }
    if (pr.distance < -reach) { deep = true; continue; }
    if (face < 0 || std::abs(pr.distance) < std::abs(best.distance)) best = pr, face = f;
  }
  where = face >= 0 ? Reach::near : deep ? Reach::deep : apart ? Reach::apart : Reach::nowhere;
  // A failed projection matters only where no candidate face placed the point
  // (in reach, apart or deep): on curved tri6 faces the projection along the
  // normal field often fails for faces the point lies beside, while a
  // neighbouring face holds it or shows it apart.
  if (failed && where == Reach::nowhere && unconverged) ++*unconverged;
  return best;
}

namespace {

// Beam elements per chunk of the threaded loop (each projects its Gauss points on
// a few faces and forms blocks of ~60 x 60).
constexpr std::size_t kContactChunk = 16;

}  // namespace

void BeamToSurfacePair::assemble(const SystemState& state, Assembler& out) {
  surface_->update(state.u);
  if (searched_points_.empty() || moved_too_far(state.u)) {
    log::debug("contact '{}': a point moved more than half the search margin ({:g} mm): searching again", name_, margin_);
    refresh_search(state.u);
  }
  const bool tangent = out.wants_tangent();
  rank_ = state.rank, ranks_ = state.ranks;
  const std::size_t ne = gauss_.size();
  // Threads project and integrate beam elements (the cost); their blocks reach the
  // assembler in element order (threads.hpp), so the sums are the one-thread loop's.
  // An element writes only its own points' active flags; the faces it reserved are
  // recorded with its blocks; the surface's normal derivatives are computed once per
  // update under its lock.
  chunks_.resize(static_cast<std::size_t>(ordered_slots()));
  int unconverged = 0;
  // The reservations of an assembly that fails here are undone: its pending entries never
  // join the pattern (the next assembly starts afresh), so those faces are still unreserved.
  std::vector<std::pair<std::size_t, std::vector<int>>> before;
  try {
    parallel_ordered(
        ne, kContactChunk,
        [&](std::size_t begin, std::size_t end, int slot) {
          Chunk& c = chunks_[static_cast<std::size_t>(slot)];
          c.used = 0;
          c.unconverged = 0;
          c.reserved.clear();
          for (std::size_t e = begin; e < end; ++e)
            if (state.owns(e, ne)) element_blocks(state, e, tangent, c);
        },
        [&](std::size_t, std::size_t, int slot) {
          Chunk& c = chunks_[static_cast<std::size_t>(slot)];
          for (std::size_t k = 0; k < c.used; ++k) out.add(c.blocks[k].dofs, c.blocks[k].r, c.blocks[k].k);
          for (auto& [e, faces] : c.reserved) {
            reserved_[e].swap(faces);
            before.emplace_back(e, std::move(faces));
          }
          unconverged += c.unconverged;
        });
  } catch (...) {
    for (auto& [e, faces] : before) reserved_[e].swap(faces);
    throw;
  }
  if (tangent) unconverged_ = unconverged;
}

BeamToSurfacePair::Block& BeamToSurfacePair::Chunk::next() {
  if (used == blocks.size()) blocks.emplace_back();
  return blocks[used++];
}

void BeamToSurfacePair::element_blocks(const SystemState& state, std::size_t e, bool tangent, Chunk& out) {
  const bool potential = settings_.form == BeamContactForm::potential;
  const int ng = settings_.gauss_points, nq = 3 * nc_;
  // The slot's scratch, reused from element to element (no allocation once sized).
  GapDerivatives& gd = out.gd;
  NormalFieldDerivatives& nd = out.nd;
  std::vector<PairBlock>& blocks = out.pairs;
  std::vector<int>& near = out.near;  // the faces this element's points project onto within reach
  blocks.clear();
  near.clear();
  const auto x = centerline(state.u, e);
  for (int q = 0; q < ng; ++q) {
    const GaussPoint& gp = gauss_[e][static_cast<std::size_t>(q)];
    const std::size_t id = e * static_cast<std::size_t>(ng) + static_cast<std::size_t>(q);
    Vec3 p = Vec3::Zero();
    for (int k = 0; k < nc_; ++k) p += gp.B[static_cast<std::size_t>(k)] * x[static_cast<std::size_t>(k)];
    int face = -1;
    Reach where = Reach::nowhere;
    const NormalProjection pr =
        project(*surface_, candidates_[e].faces, p, face, where, tangent ? &out.unconverged : nullptr, &face_boxes_);
    // A point in contact in the last converged state that now projects nowhere, or far through the
    // surface, would silently lose its force: a failed iteration instead (the step is cut).
    if (active_.committed(id) && (where == Reach::nowhere || where == Reach::deep))
      throw ElementFailure(fmt::format("contact '{}': Gauss point {} of beam element {} at ({:.4g}, {:.4g}, {:.4g}) was in "
                                       "contact in the last converged state but {} now",
                                       name_, q, e, p.x(), p.y(), p.z(),
                                       where == Reach::deep ? fmt::format("lies more than the search reach inside '{}'", surface_->name())
                                                            : fmt::format("projects onto no face of '{}'", surface_->name())));
    if (face >= 0) near.push_back(face);
    const bool active = face >= 0 && pr.distance - settings_.radius < settings_.law.active_limit();
    // The active set of Newton iterates (tangent assemblies), not of line-search trials.
    if (tangent) {
      const int changes = active_.evaluate(id, active);
      if (changes > settings_.max_flips)
        throw ElementFailure(fmt::format("contact '{}': Gauss point {} of beam element {} switched in and out of contact {} "
                                         "times in this step (active-set chattering; max_flips = {})", name_, q, e, changes,
                                         settings_.max_flips));
    }
    if (!active) continue;
    double phi, d1, d2;
    settings_.law.eval(pr.distance - settings_.radius, phi, d1, d2);
    const int nf = surface_->faces()[static_cast<std::size_t>(face)].count;
    auto it = std::find_if(blocks.begin(), blocks.end(), [&](const PairBlock& b) { return b.face == face; });
    if (it == blocks.end()) {
      const int n = nq + 6 * nf;
      blocks.push_back({face, Eigen::VectorXd::Zero(n), tangent ? Eigen::MatrixXd::Zero(n, n) : Eigen::MatrixXd()});
      it = blocks.end() - 1;
    }
    // v = (p, x_k, n_k) -> v' = (q, x_k, n_k) with p = Σ B_j q_j.
    const double w = gp.weight;
    const int nr = 6 * nf;
    if (settings_.form == BeamContactForm::gap_variation) {
      normal_field_derivatives(*surface_, face, pr, tangent, nd);
      for (int j = 0; j < nc_; ++j) it->g.segment<3>(3 * j) += w * d1 * gp.B[static_cast<std::size_t>(j)] * nd.normal;
      for (int k = 0; k < nf; ++k) it->g.segment<3>(nq + 3 * k) -= w * d1 * nd.n[static_cast<std::size_t>(k)] * nd.normal;
      if (!tangent) continue;
      // Rows (beam vectors q_j, face nodes x_k) against columns v = (p, x_k, n_k).
      const int N = 3 + nr;
      Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(nq + 3 * nf, N);
      const Eigen::MatrixXd beam_row = d2 * nd.normal * nd.gap_grad.transpose() + d1 * nd.dnormal;
      for (int j = 0; j < nc_; ++j) rows.middleRows<3>(3 * j) = w * gp.B[static_cast<std::size_t>(j)] * beam_row;
      for (int k = 0; k < nf; ++k) {
        const double nk = nd.n[static_cast<std::size_t>(k)];
        rows.middleRows<3>(nq + 3 * k) = -w * (nk * beam_row + d1 * nd.normal * nd.dshape.row(k));
      }
      // Columns: p -> q_b (× B_b); x_k, n_k as they are.
      for (int b = 0; b < nc_; ++b)
        it->k.block(0, 3 * b, nq + 3 * nf, 3) += gp.B[static_cast<std::size_t>(b)] * rows.leftCols<3>();
      it->k.block(0, nq, nq + 3 * nf, nr) += rows.rightCols(nr);
      continue;
    }
    gap_derivatives(*surface_, face, pr, tangent, gd);
    for (int j = 0; j < nc_; ++j) it->g.segment<3>(3 * j) += w * d1 * gp.B[static_cast<std::size_t>(j)] * gd.grad.head<3>();
    it->g.segment(nq, nr) += w * d1 * gd.grad.tail(nr);
    if (!tangent) continue;
    const Eigen::MatrixXd h = w * (d2 * gd.grad * gd.grad.transpose() + d1 * gd.hess);
    for (int a = 0; a < nc_; ++a) {
      const double ba = gp.B[static_cast<std::size_t>(a)];
      for (int b = 0; b < nc_; ++b) it->k.block<3, 3>(3 * a, 3 * b) += ba * gp.B[static_cast<std::size_t>(b)] * h.block<3, 3>(0, 0);
      it->k.block(3 * a, nq, 3, nr) += ba * h.block(0, 3, 3, nr);
      it->k.block(nq, 3 * a, nr, 3) += ba * h.block(3, 0, nr, 3);
    }
    it->k.block(nq, nq, nr, nr) += h.block(3, 3, nr, nr);
  }
  // Scatter each pair through T = ∂v'/∂(DOFs); reserve the pattern of candidate pairs with no active point.
  const std::vector<GlobalDof> beam_dofs = beam_.element_dofs(e);
  auto patch_of = [&](int face, std::vector<int>& patch) {
    const SurfaceFace& f = surface_->faces()[static_cast<std::size_t>(face)];
    patch.clear();
    for (int k = 0; k < f.count; ++k) {
      const auto& nd = surface_->normal_derivatives(f.node[k], potential);
      patch.insert(patch.end(), nd.patch.begin(), nd.patch.end());
    }
    std::sort(patch.begin(), patch.end());
    patch.erase(std::unique(patch.begin(), patch.end()), patch.end());
  };
  auto dofs_of = [&](const std::vector<int>& patch) {
    std::vector<GlobalDof> d(beam_dofs.begin(), beam_dofs.begin() + nq);
    for (int n : patch)
      for (int c = 0; c < 3; ++c) d.push_back(surface_->dof(n, c));
    return d;
  };
  std::vector<int>& patch = out.patch;
  for (const PairBlock& b : blocks) {
    const SurfaceFace& f = surface_->faces()[static_cast<std::size_t>(b.face)];
    patch_of(b.face, patch);
    auto slot = [&](int n) { return nq + 3 * static_cast<int>(std::lower_bound(patch.begin(), patch.end(), n) - patch.begin()); };
    const int M = nq + 3 * static_cast<int>(patch.size()), nv = nq + 6 * f.count;
    // T = ∂v'/∂(DOFs) by its 3 x 3 blocks, never formed: per triple t of v' the (column slot,
    // block) pairs — identity for the beam vectors and the face nodes, the nodal normals'
    // Jacobian blocks over their patches. Applied to columns (K' T) and to rows (Tᵀ ·).
    std::vector<std::vector<std::pair<int, Mat3>>> map(static_cast<std::size_t>(nv / 3));
    for (int t = 0; t < nq / 3; ++t) map[static_cast<std::size_t>(t)].emplace_back(3 * t, Mat3::Identity());
    for (int k = 0; k < f.count; ++k) {
      map[static_cast<std::size_t>(nq / 3 + k)].emplace_back(slot(f.node[k]), Mat3::Identity());
      const NormalDerivatives& nd = surface_->normal_derivatives(f.node[k], potential);
      auto& nk = map[static_cast<std::size_t>(nq / 3 + f.count + k)];
      for (std::size_t m = 0; m < nd.patch.size(); ++m)
        nk.emplace_back(slot(nd.patch[m]), nd.jacobian.block<3, 3>(0, 3 * static_cast<int>(m)));
    }
    // Gap variation: no residual on the normals (their rows of g' and K' are zero).
    const int row_triples = potential ? nv / 3 : nq / 3 + f.count;
    Eigen::VectorXd r = Eigen::VectorXd::Zero(M);
    for (int t = 0; t < row_triples; ++t)
      for (const auto& [col, J] : map[static_cast<std::size_t>(t)]) r.segment<3>(col) += J.transpose() * b.g.segment<3>(3 * t);
    Eigen::MatrixXd K;
    if (tangent) {
      Eigen::MatrixXd KT = Eigen::MatrixXd::Zero(3 * row_triples, M);
      for (int t = 0; t < nv / 3; ++t)
        for (const auto& [col, J] : map[static_cast<std::size_t>(t)])
          KT.middleCols<3>(col) += b.k.block(0, 3 * t, 3 * row_triples, 3) * J;
      K = Eigen::MatrixXd::Zero(M, M);
      for (int t = 0; t < row_triples; ++t)
        for (const auto& [row, J] : map[static_cast<std::size_t>(t)]) K.middleRows<3>(row) += J.transpose() * KT.middleRows<3>(3 * t);
      for (int k = 0; k < f.count && potential; ++k) {
        const NormalDerivatives& nd = surface_->normal_derivatives(f.node[k], true);
        std::vector<int> s(nd.patch.size());
        for (std::size_t m = 0; m < nd.patch.size(); ++m) s[m] = slot(nd.patch[m]);
        for (int c = 0; c < 3; ++c) {
          const double gc = b.g[nq + 3 * f.count + 3 * k + c];
          if (gc == 0.0) continue;
          for (std::size_t i = 0; i < s.size(); ++i)
            for (std::size_t j = 0; j < s.size(); ++j)
              K.block<3, 3>(s[i], s[j]) += gc * nd.hessian[c].block<3, 3>(3 * static_cast<int>(i), 3 * static_cast<int>(j));
        }
      }
    }
    Block& blk = out.next();
    blk.dofs = dofs_of(patch);
    blk.r = std::move(r);
    blk.k = std::move(K);
  }
  if (tangent) {
    // Reserve the pattern of the faces a point is near but not yet pressed on, so that its
    // contact usually starts inside the pattern the solver has analysed. Only these: all the
    // search's candidate faces (every face within the margin of the element's box) made the
    // matrix 40 % larger and its LU fill 25 % (free expansion: 1.45 M against 1.04 M entries).
    // The global pattern only grows, so a pair reserved once keeps its entries. The record
    // is updated when the blocks reach the assembler (a chunk computed after a failing one
    // never does) and undone if this pair's assembly fails (not if a later term's does: then
    // the faces stay marked and their pattern comes with their first contact).
    const std::vector<int>& done = reserved_[e];
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    bool added = false;
    for (int face : near) {
      if (std::binary_search(done.begin(), done.end(), face)) continue;
      added = true;
      if (std::any_of(blocks.begin(), blocks.end(), [&](const PairBlock& b) { return b.face == face; })) continue;
      patch_of(face, patch);
      Block& blk = out.next();
      blk.dofs = dofs_of(patch);
      const auto n = static_cast<Eigen::Index>(blk.dofs.size());
      blk.r.setZero(n);
      blk.k.setZero(n, n);
    }
    if (added) {
      std::vector<int> merged;
      std::set_union(done.begin(), done.end(), near.begin(), near.end(), std::back_inserter(merged));
      out.reserved.emplace_back(e, std::move(merged));
    }
  }
}

std::vector<BeamContactPoint> BeamToSurfacePair::evaluate(const Eigen::VectorXd& u) const {
  ContactSurface surface = *surface_;
  surface.update(u);
  std::vector<Candidates> cand;
  search(surface, u, cand);
  std::vector<BeamContactPoint> pts;
  GapDerivatives gd;
  for (std::size_t e = 0; e < gauss_.size(); ++e) {
    const auto x = centerline(u, e);
    for (int q = 0; q < settings_.gauss_points; ++q) {
      const GaussPoint& gp = gauss_[e][static_cast<std::size_t>(q)];
      BeamContactPoint c;
      c.element = e, c.gauss_point = q, c.xi = gp.xi, c.weight = gp.weight;
      for (int k = 0; k < nc_; ++k) c.position += gp.B[static_cast<std::size_t>(k)] * x[static_cast<std::size_t>(k)];
      Reach where = Reach::nowhere;
      const NormalProjection pr = project(surface, cand[e].faces, c.position, c.face, where);
      c.deep = where == Reach::deep;
      if (c.face >= 0) {
        c.projected = true;
        c.gap = pr.distance - settings_.radius;
        double phi, d1, d2;
        settings_.law.eval(c.gap, phi, d1, d2);
        c.active = c.gap < settings_.law.active_limit();
        if (c.active) {
          if (settings_.form == BeamContactForm::gap_variation) {
            c.line_load = -d1 * pr.direction;
          } else {
            gap_derivatives(surface, c.face, pr, false, gd);
            c.line_load = -d1 * gd.grad.head<3>();
          }
        }
      }
      pts.push_back(c);
    }
  }
  return pts;
}

void BeamToSurfacePair::commit() {
  active_.commit(static_cast<std::size_t>(settings_.gauss_points), rank_, ranks_);
  if (unconverged_ > 0)
    log::warn("contact '{}': {} points within their candidate faces' boxes projected inside none of them, and onto some not at all, in the "
              "converged state (they count as out of contact there)", name_, unconverged_);
}

void BeamToSurfacePair::save_history(HistoryArchive& out, const std::string& prefix) const {
  active_.save(out, prefix + "active");
}

void BeamToSurfacePair::load_history(const HistoryArchive& in, const std::string& prefix) {
  active_.load(in, prefix + "active");
}

}  // namespace stentsim::solver::contact
