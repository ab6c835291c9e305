#include "solver/assembly/global_system.hpp"

#include "common/log.hpp"
#include "solver/assembly/parallel.hpp"
#include "solver/assembly/threads.hpp"

#include <algorithm>
#include <cmath>

namespace stentsim::solver {

GlobalSystem::GlobalSystem(const Constraints& constraints) : constraints_(constraints) {
  const GlobalDof n = constraints_.size();
  matrix_.rows = n;
  matrix_.row_ptr.assign(static_cast<std::size_t>(n) + 1, 0);
}

void GlobalSystem::begin(const Eigen::VectorXd& prescribed, bool with_tangent) {
  const GlobalDof n = constraints_.size();
  residual_.setZero(n);
  magnitude_.setZero(n);
  correction_.setZero(n);
  prescribed_ = prescribed;
  with_tangent_ = with_tangent;
  std::fill(matrix_.values.begin(), matrix_.values.end(), 0.0);
  pending_.clear();
  laying_.clear();
}

bool GlobalSystem::pattern_laid(const void* term) const { return std::find(laid_.begin(), laid_.end(), term) != laid_.end(); }

void GlobalSystem::insert(GlobalDof row, GlobalDof col, double value) {
  const auto k = matrix_.find(row, col);
  if (k >= 0) matrix_.values[static_cast<std::size_t>(k)] += value;
  else pending_.emplace_back(row, col, value);
}

template <class Hold>
void GlobalSystem::scatter(Scratch& scratch, std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& r_in,
                           const Eigen::Ref<const Eigen::MatrixXd>& k_in, Hold&& hold) {
  const auto n = static_cast<Eigen::Index>(dofs.size());
  const bool tangent = with_tangent_ && k_in.size() > 0;
  // Nodal frames: rotate node triples of the element to local coordinates.
  bool rotate = false;
  if (constraints_.has_frames())
    for (Eigen::Index i = 0; i + 2 < n && !rotate; ++i)
      rotate = dofs[static_cast<std::size_t>(i)] >= 0 && constraints_.frame_start(dofs[static_cast<std::size_t>(i)]) &&
               dofs[static_cast<std::size_t>(i) + 1] == dofs[static_cast<std::size_t>(i)] + 1 &&
               dofs[static_cast<std::size_t>(i) + 2] == dofs[static_cast<std::size_t>(i)] + 2;
  const Eigen::VectorXd* r = nullptr;
  const Eigen::MatrixXd* k = nullptr;
  Eigen::Ref<const Eigen::VectorXd> rr = r_in;
  Eigen::Ref<const Eigen::MatrixXd> kr = k_in;
  if (rotate) {
    scratch.r = r_in;
    if (tangent) scratch.k = k_in;
    for (Eigen::Index i = 0; i + 2 < n; ++i) {
      const GlobalDof d = dofs[static_cast<std::size_t>(i)];
      if (d < 0 || !constraints_.frame_start(d) || dofs[static_cast<std::size_t>(i) + 1] != d + 1 ||
          dofs[static_cast<std::size_t>(i) + 2] != d + 2)
        continue;
      const Mat3& q = *constraints_.frame(d);
      scratch.r.segment<3>(i) = q.transpose() * scratch.r.segment<3>(i);
      if (tangent) {
        scratch.k.middleRows<3>(i) = q.transpose() * scratch.k.middleRows<3>(i);
        scratch.k.middleCols<3>(i) = scratch.k.middleCols<3>(i) * q;
      }
      i += 2;
    }
    r = &scratch.r;
    k = &scratch.k;
  }
  auto rv = [&](Eigen::Index i) { return r ? (*r)(i) : rr(i); };
  auto kv = [&](Eigen::Index i, Eigen::Index j) { return k ? (*k)(i, j) : kr(i, j); };
  for (Eigen::Index i = 0; i < n; ++i) {
    const GlobalDof gi = dofs[static_cast<std::size_t>(i)];
    if (gi < 0) continue;
    residual_(gi) += rv(i);
    if (with_tangent_) magnitude_(gi) += std::abs(rv(i));
  }
  if (!tangent) return;
  // The block's free columns in DOF order, so that each row is one forward walk
  // through its sorted CSR columns (a node's x, y, z are neighbours there)
  // instead of a binary search per entry; fixed columns go to the correction.
  scratch.free_cols.clear();
  scratch.fixed_cols.clear();
  for (Eigen::Index j = 0; j < n; ++j) {
    const GlobalDof gj = dofs[static_cast<std::size_t>(j)];
    if (gj < 0) continue;
    (constraints_.fixed(gj) ? scratch.fixed_cols : scratch.free_cols).emplace_back(gj, j);
  }
  std::sort(scratch.free_cols.begin(), scratch.free_cols.end());
  const std::int64_t* cols = matrix_.cols.data();
  for (Eigen::Index i = 0; i < n; ++i) {
    const GlobalDof gi = dofs[static_cast<std::size_t>(i)];
    if (gi < 0 || constraints_.fixed(gi)) continue;
    for (const auto& [gj, j] : scratch.fixed_cols) correction_(gi) += kv(i, j) * prescribed_(gj);
    std::int64_t pos = matrix_.row_ptr[static_cast<std::size_t>(gi)];
    const std::int64_t end = matrix_.row_ptr[static_cast<std::size_t>(gi) + 1];
    for (const auto& [gj, j] : scratch.free_cols) {
      if (pos < end && cols[pos] < gj && (++pos < end && cols[pos] < gj)) pos = std::lower_bound(cols + pos, cols + end, gj) - cols;
      if (pos < end && cols[pos] == gj) matrix_.values[static_cast<std::size_t>(pos)] += kv(i, j);
      else hold(gi, gj, kv(i, j));
    }
  }
}

void GlobalSystem::add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& r_in,
                       const Eigen::Ref<const Eigen::MatrixXd>& k_in) {
  scatter(scratch_, dofs, r_in, k_in, [this](GlobalDof i, GlobalDof j, double v) { pending_.emplace_back(i, j, v); });
  if (pending_.size() > compact_at_) compact_pending();
}

ConcurrentAssembler* GlobalSystem::concurrent() {
  const auto n = static_cast<std::size_t>(assembly_threads());
  while (lanes_.size() < n) lanes_.emplace_back(*this);
  return this;
}

Assembler& GlobalSystem::lane(int thread, std::size_t order) {
  Lane& l = lanes_.at(static_cast<std::size_t>(thread));
  l.order = order;
  return l;
}

void GlobalSystem::Lane::add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& r_in,
                             const Eigen::Ref<const Eigen::MatrixXd>& k_in) {
  system_->scatter(scratch, dofs, r_in, k_in, [this](GlobalDof i, GlobalDof j, double v) { held.emplace_back(order, i, j, v); });
}

void GlobalSystem::merge() {
  std::vector<std::tuple<std::size_t, GlobalDof, GlobalDof, double>> all;
  for (Lane& l : lanes_) {
    all.insert(all.end(), l.held.begin(), l.held.end());
    l.held.clear();
  }
  if (all.empty()) return;
  // In block order, and inside a block as its lane added them: the serial add()'s order
  // over the coloured sequence, whichever thread took which block.
  std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });
  pending_.reserve(pending_.size() + all.size());
  for (const auto& [order, i, j, v] : all) pending_.emplace_back(i, j, v);
  if (pending_.size() > compact_at_) compact_pending();
}

void GlobalSystem::compact_pending() {
  std::stable_sort(pending_.begin(), pending_.end(), [](const auto& a, const auto& b) {
    return std::get<0>(a) != std::get<0>(b) ? std::get<0>(a) < std::get<0>(b) : std::get<1>(a) < std::get<1>(b);
  });
  std::size_t out = 0;
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    if (out > 0 && std::get<0>(pending_[out - 1]) == std::get<0>(pending_[k]) && std::get<1>(pending_[out - 1]) == std::get<1>(pending_[k]))
      std::get<2>(pending_[out - 1]) += std::get<2>(pending_[k]);
    else
      pending_[out++] = pending_[k];
  }
  pending_.resize(out);
  compact_at_ = std::max(compact_at_, 2 * out);
}

void GlobalSystem::finish() {
  if (ranks_ > 1) {
    parallel::sum(residual_);
    if (with_tangent_) parallel::sum(magnitude_);
    if (with_tangent_) parallel::sum(correction_);
  }
  if (!with_tangent_) return;
  const GlobalDof n = constraints_.size();
  for (GlobalDof d = 0; d < n; ++d)
    if (constraints_.fixed(d)) insert(d, d, 0.0);  // identity set below
  if (!pending_.empty()) {
    const std::int64_t before = matrix_.nonzeros();
    // Rebuild the pattern as the union of the old one and the new entries.
    std::vector<std::vector<std::pair<std::int64_t, double>>> rows(static_cast<std::size_t>(n));
    for (GlobalDof i = 0; i < n; ++i)
      for (auto k = matrix_.row_ptr[static_cast<std::size_t>(i)]; k < matrix_.row_ptr[static_cast<std::size_t>(i) + 1]; ++k)
        rows[static_cast<std::size_t>(i)].emplace_back(matrix_.cols[static_cast<std::size_t>(k)], matrix_.values[static_cast<std::size_t>(k)]);
    for (const auto& [i, j, v] : pending_) rows[static_cast<std::size_t>(i)].emplace_back(j, v);
    matrix_.row_ptr.assign(static_cast<std::size_t>(n) + 1, 0);
    matrix_.cols.clear();
    matrix_.values.clear();
    for (GlobalDof i = 0; i < n; ++i) {
      auto& row = rows[static_cast<std::size_t>(i)];
      // Stable: a repeated entry sums in the order it was added, as inside the pattern.
      std::stable_sort(row.begin(), row.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      for (std::size_t k = 0; k < row.size(); ++k) {
        if (k > 0 && row[k].first == row[k - 1].first) {
          matrix_.values.back() += row[k].second;
          continue;
        }
        matrix_.cols.push_back(row[k].first);
        matrix_.values.push_back(row[k].second);
      }
      matrix_.row_ptr[static_cast<std::size_t>(i) + 1] = static_cast<std::int64_t>(matrix_.cols.size());
      std::vector<std::pair<std::int64_t, double>>().swap(row);
    }
    ++matrix_.pattern_version;
    log::debug("matrix pattern grew by {} entries to {} (the linear solver analyses it again)", matrix_.nonzeros() - before,
               matrix_.nonzeros());
    pending_.clear();
  }
  for (GlobalDof d = 0; d < n; ++d)
    if (constraints_.fixed(d)) matrix_.values[static_cast<std::size_t>(matrix_.find(d, d))] = rank_ == 0 ? 1.0 : 0.0;
  laid_.insert(laid_.end(), laying_.begin(), laying_.end());
  laying_.clear();
}

double GlobalSystem::free_residual_norm() const {
  double s = 0.0;
  for (GlobalDof d = 0; d < residual_.size(); ++d)
    if (!constraints_.fixed(d)) s += residual_(d) * residual_(d);
  return std::sqrt(s);
}

double GlobalSystem::force_magnitude_norm() const {
  double s = 0.0;
  for (GlobalDof d = 0; d < magnitude_.size(); ++d)
    if (!constraints_.fixed(d)) s += magnitude_(d) * magnitude_(d);
  return std::sqrt(s);
}

Eigen::VectorXd GlobalSystem::rhs() const {
  Eigen::VectorXd b(residual_.size());
  for (GlobalDof d = 0; d < residual_.size(); ++d)
    b(d) = constraints_.fixed(d) ? prescribed_(d) : -(residual_(d) + correction_(d));
  return b;
}

}  // namespace stentsim::solver
