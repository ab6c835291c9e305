#include "solver/terms/solid_body.hpp"

#include <Eigen/Eigenvalues>

#include <array>
#include <limits>
#include <mutex>
#include <string>

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/assembly/colouring.hpp"
#include "solver/assembly/parallel.hpp"
#include "solver/assembly/threads.hpp"
#include "solver/terms/element_failure.hpp"
#include "solver/terms/solid_kernel.hpp"

namespace stentsim::solver {
namespace {

bool is_volume(CellType t) {
  return t == CellType::hexahedron || t == CellType::tetra || t == CellType::quadratic_tetra;
}

int points_of(CellType t) {
  switch (t) {
    case CellType::hexahedron: return fem::Hex8::kRule.kPoints;
    case CellType::tetra: return fem::Tet4::kRule.kPoints;
    case CellType::quadratic_tetra: return fem::Tet10::kRule.kPoints;
    default: return 0;
  }
}

}  // namespace

SolidBody::SolidBody(SolidBodySpec spec, GlobalDof first_dof)
    : name_(std::move(spec.name)),
      mesh_(std::move(spec.mesh)),
      materials_(std::move(spec.materials)),
      cell_material_(std::move(spec.cell_material)),
      first_dof_(first_dof) {
  if (cell_material_.size() != mesh_.num_cells())
    throw InputError(fmt::format("body '{}': {} material indices for {} cells", name_, cell_material_.size(), mesh_.num_cells()));
  std::array<Vec3, kMaxFiberFamilies> none;
  none.fill(Vec3::Zero());
  fiber_dirs_.assign(mesh_.num_cells(), none);
  long long slots = 0;
  for (std::size_t c = 0; c < mesh_.num_cells(); ++c) {
    const int m = cell_material_[c];
    if (m < 0) continue;
    if (m >= static_cast<int>(materials_.size()))
      throw InputError(fmt::format("body '{}': cell {} refers to material {} of {}", name_, c, m, materials_.size()));
    if (!is_volume(mesh_.cell_types[c]))
      throw InputError(fmt::format("body '{}': cell {} has VTK type {}, expected a volume cell (hex8, tet4, tet10)",
                                   name_, c, static_cast<int>(mesh_.cell_types[c])));
    const Material& mat = materials_[static_cast<std::size_t>(m)];
    if (mat.fibers.size() > static_cast<std::size_t>(kMaxFiberFamilies))
      throw InputError(fmt::format("material '{}' has {} fiber families; at most {}", mat.name, mat.fibers.size(), kMaxFiberFamilies));
    for (std::size_t f = 0; f < mat.fibers.size(); ++f) {
      const auto& fam = mat.fibers[f];
      Vec3 a;
      if (fam.global_direction) {
        a = *fam.global_direction;
      } else if (!spec.cell_fibers.empty()) {
        if (spec.cell_fibers.size() != mesh_.num_cells() || static_cast<int>(f) >= spec.fibers_per_cell)
          throw InputError(fmt::format("body '{}': material '{}' has {} fiber families but the fiber field gives {} "
                                       "direction(s) per cell", name_, mat.name, mat.fibers.size(), spec.fibers_per_cell));
        a = spec.cell_fibers[c][f];
      } else {
        if (spec.cell_frames.size() != mesh_.num_cells())
          throw InputError(fmt::format("body '{}': material '{}' gives fiber angles but the body has no local "
                                       "(radial, circumferential, longitudinal) frames", name_, mat.name));
        const double phi = fam.angle_deg * std::numbers::pi / 180.0;
        a = std::cos(phi) * spec.cell_frames[c][1] + std::sin(phi) * spec.cell_frames[c][2];
      }
      if (!(a.norm() > 1e-12)) throw InputError(fmt::format("body '{}': cell {} has a zero fiber direction", name_, c));
      fiber_dirs_[c][f] = a.normalized();
    }
    Element el{c, m, -1};
    if (mat.viscous) {
      el.history = slots;
      slots += points_of(mesh_.cell_types[c]);
    }
    elements_.push_back(el);
  }
  committed_.assign(static_cast<std::size_t>(slots), ViscousHistory{});
  trial_ = committed_;
}

Vec3 SolidBody::position(const Eigen::VectorXd& u, std::size_t node) const {
  return mesh_.points[node] + u.segment<3>(dof(node, 0));
}

void SolidBody::fail(const Element& el, const char* type, int point, int corner, const char* why) const {
  std::string where;
  if (point >= 0) where = fmt::format(", quadrature point {}", point);
  else if (corner >= 0)
    where = fmt::format(", corner node {}",
                        mesh_.connectivity[static_cast<std::size_t>(mesh_.cell_offsets[el.cell]) + static_cast<std::size_t>(corner)]);
  throw ElementFailure(fmt::format("body '{}', element {} ({}, material '{}'){}: {}", name_, el.cell, type,
                                   materials_[static_cast<std::size_t>(el.material)].name, where, why));
}

template <class E>
void SolidBody::assemble_element(const Element& el, const SystemState& state, Assembler& out, bool tangent) {
  using K = SolidElement<E>;
  typename K::NodeMat xr, xc;
  std::array<GlobalDof, K::kDofs> dofs;
  const std::int64_t* conn = &mesh_.connectivity[static_cast<std::size_t>(mesh_.cell_offsets[el.cell])];
  for (int i = 0; i < E::kNodes; ++i) {
    const auto node = static_cast<std::size_t>(conn[i]);
    xr.col(i) = mesh_.points[node];
    for (int a = 0; a < 3; ++a) dofs[3 * i + a] = dof(node, a);
    xc.col(i) = xr.col(i) + state.u.segment<3>(dofs[3 * i]);
  }
  typename K::Vec r;
  typename K::Mat k;
  const ViscousHistory* hist = el.history >= 0 ? &committed_[static_cast<std::size_t>(el.history)] : nullptr;
  ViscousHistory* trial = el.history >= 0 ? &trial_[static_cast<std::size_t>(el.history)] : nullptr;
  const auto res = K::evaluate(xr, xc, materials_[static_cast<std::size_t>(el.material)], fiber_dirs_[el.cell].data(),
                               hist, trial, state.dt, r, tangent ? &k : nullptr);
  if (!res.status.ok) fail(el, E::kName, res.point, res.corner, res.status.why);
  if (!r.allFinite() || (tangent && !k.allFinite())) fail(el, E::kName, -1, -1, "residual or tangent not finite");
  if (tangent) out.add(dofs, r, k);
  else out.add(dofs, r, Eigen::MatrixXd());
}

void SolidBody::assemble_any(const Element& el, const SystemState& state, Assembler& out, bool tangent) {
  switch (mesh_.cell_types[el.cell]) {
    case CellType::hexahedron: assemble_element<fem::Hex8>(el, state, out, tangent); break;
    case CellType::tetra: assemble_element<fem::Tet4>(el, state, out, tangent); break;
    case CellType::quadratic_tetra: assemble_element<fem::Tet10>(el, state, out, tangent); break;
    default: break;
  }
}

void SolidBody::colour_chunks() {
  const std::size_t n = elements_.size();
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::int64_t> nodes;
  chunk_colours_ = colour_by_nodes(chunks, mesh_.points.size(), [&](std::size_t c) {
    nodes.clear();
    for (std::size_t e = c * kChunk; e < std::min(n, (c + 1) * kChunk); ++e) {
      const std::size_t cell = elements_[e].cell;
      nodes.insert(nodes.end(), mesh_.connectivity.begin() + mesh_.cell_offsets[cell],
                   mesh_.connectivity.begin() + mesh_.cell_offsets[cell + 1]);
    }
    return std::span<const std::int64_t>(nodes);
  });
  chunk_order_.assign(chunks, 0);
  std::size_t order = 0;
  for (const auto& colour : chunk_colours_)
    for (const std::uint32_t c : colour) {
      chunk_order_[c] = order;
      order += std::min(n, (c + 1) * kChunk) - c * kChunk;
    }
  log::debug("body '{}': {} elements in {} chunks of {}, {} colours (threaded assembly)", name_, n, chunks, kChunk,
             chunk_colours_.size());
}

void SolidBody::assemble(const SystemState& state, Assembler& out) {
  rank_ = state.rank, ranks_ = state.ranks;
  const bool tangent = out.wants_tangent();
  const std::size_t n = elements_.size();
  ConcurrentAssembler* lanes = assembly_threads() > 1 ? out.concurrent() : nullptr;
  if (!lanes || !lanes->pattern_laid(this)) {
    for (std::size_t e = 0; e < n; ++e)
      if (state.owns(e, n)) assemble_any(elements_[e], state, out, tangent);
    if (lanes && tangent) lanes->laid(this);
    return;
  }
  // Threaded: runs of consecutive elements (chunks) are coloured by the nodes they
  // share, so the chunks of one colour scatter into disjoint rows, each chunk in element
  // order (neighbouring elements share rows: a chunk keeps them in cache, where
  // colouring single elements would send every block to rows no other nearby block
  // touches). Every matrix entry is summed in the coloured order whatever the thread
  // count (colouring.hpp). A failing element stops the loop after its colour; the
  // first in that order is reported, as the serial loop reports the first in its own.
  if (chunk_colours_.empty()) colour_chunks();
  std::mutex failure_mutex;
  std::size_t failure_order = std::numeric_limits<std::size_t>::max();
  std::string failure;
  for (const auto& colour : chunk_colours_) {
    parallel_ranges(colour.size(), 1, [&](std::size_t begin, std::size_t end) {
      const int thread = assembly_thread_index();
      for (std::size_t i = begin; i < end; ++i) {
        const std::size_t chunk = colour[i];
        const std::size_t e0 = chunk * kChunk, e1 = std::min(n, e0 + kChunk);
        for (std::size_t e = e0; e < e1; ++e) {
          if (!state.owns(e, n)) continue;
          const std::size_t order = chunk_order_[chunk] + (e - e0);
          try {
            assemble_any(elements_[e], state, lanes->lane(thread, order), tangent);
          } catch (const ElementFailure& f) {
            const std::lock_guard<std::mutex> lock(failure_mutex);
            if (order < failure_order) failure_order = order, failure = f.what();
            return;
          }
        }
      }
    });
    if (!failure.empty()) throw ElementFailure(failure);
  }
  lanes->merge();
}

void SolidBody::commit() {
  if (ranks_ > 1 && !committed_.empty()) {
    // Owned slots carry this rank's trial history, the others zero; the sum over ranks is the whole history.
    Eigen::VectorXd v = Eigen::VectorXd::Zero(12 * static_cast<Eigen::Index>(trial_.size()));
    const Eigen::VectorXd none;
    SystemState owner{none, 0.0, 0.0, rank_, ranks_};
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      const Element& el = elements_[e];
      if (el.history < 0 || !owner.owns(e, elements_.size())) continue;
      for (int q = 0; q < points_of(mesh_.cell_types[el.cell]); ++q) {
        const auto slot = static_cast<Eigen::Index>(el.history + q);
        v.segment<6>(12 * slot) = trial_[static_cast<std::size_t>(slot)].q;
        v.segment<6>(12 * slot + 6) = trial_[static_cast<std::size_t>(slot)].s_inf;
      }
    }
    parallel::sum(v);
    for (std::size_t k = 0; k < trial_.size(); ++k)
      trial_[k] = {v.segment<6>(12 * static_cast<Eigen::Index>(k)), v.segment<6>(12 * static_cast<Eigen::Index>(k) + 6)};
  }
  committed_ = trial_;
}

void SolidBody::save_history(HistoryArchive& out, const std::string& prefix) const {
  std::vector<double> v;
  v.reserve(12 * committed_.size());
  for (const auto& h : committed_) {
    v.insert(v.end(), h.q.data(), h.q.data() + 6);
    v.insert(v.end(), h.s_inf.data(), h.s_inf.data() + 6);
  }
  out.put(prefix + "viscous_q_s_inf", v);
}

void SolidBody::load_history(const HistoryArchive& in, const std::string& prefix) {
  const auto& v = in.get(prefix + "viscous_q_s_inf", 12 * static_cast<long long>(committed_.size()));
  for (std::size_t k = 0; k < committed_.size(); ++k) {
    committed_[k].q = Eigen::Map<const Vec6>(&v[12 * k]);
    committed_[k].s_inf = Eigen::Map<const Vec6>(&v[12 * k + 6]);
  }
  trial_ = committed_;
}

template <class E>
void SolidBody::cell_average(const Element& el, const Eigen::VectorXd& u, Mat3& cauchy, Mat3& strain,
                             double& max_principal) const {
  using K = SolidElement<E>;
  typename K::NodeMat xr, xc;
  const std::int64_t* conn = &mesh_.connectivity[static_cast<std::size_t>(mesh_.cell_offsets[el.cell])];
  for (int i = 0; i < E::kNodes; ++i) {
    const auto node = static_cast<std::size_t>(conn[i]);
    xr.col(i) = mesh_.points[node];
    xc.col(i) = position(u, node);
  }
  const ViscousHistory* hist = el.history >= 0 ? &committed_[static_cast<std::size_t>(el.history)] : nullptr;
  double volume = 0.0;
  std::array<Mat3, K::kPoints> points;
  const auto res = K::averages(xr, xc, materials_[static_cast<std::size_t>(el.material)], fiber_dirs_[el.cell].data(),
                               hist, cauchy, strain, volume, points.data());
  if (!res.status.ok) fail(el, E::kName, res.point, res.corner, res.status.why);
  max_principal = -std::numeric_limits<double>::infinity();
  for (const Mat3& sigma : points)
    max_principal = std::max(max_principal, Eigen::SelfAdjointEigenSolver<Mat3>(sigma, Eigen::EigenvaluesOnly).eigenvalues()[2]);
}

SolidCellFields SolidBody::cell_fields(const Eigen::VectorXd& u) const {
  SolidCellFields out;
  out.cauchy.assign(mesh_.num_cells(), Mat3::Zero());
  out.strain.assign(mesh_.num_cells(), Mat3::Zero());
  out.max_principal_gauss.assign(mesh_.num_cells(), 0.0);
  for (const Element& el : elements_) {
    Mat3 &c = out.cauchy[el.cell], &e = out.strain[el.cell];
    double& m = out.max_principal_gauss[el.cell];
    switch (mesh_.cell_types[el.cell]) {
      case CellType::hexahedron: cell_average<fem::Hex8>(el, u, c, e, m); break;
      case CellType::tetra: cell_average<fem::Tet4>(el, u, c, e, m); break;
      case CellType::quadratic_tetra: cell_average<fem::Tet10>(el, u, c, e, m); break;
      default: break;
    }
  }
  return out;
}

}  // namespace stentsim::solver
