#include "solver/assembly/global_system.hpp"

#include "common/log.hpp"
#include "solver/assembly/parallel.hpp"

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
}

void GlobalSystem::insert(GlobalDof row, GlobalDof col, double value) {
  const auto k = matrix_.find(row, col);
  if (k >= 0) matrix_.values[static_cast<std::size_t>(k)] += value;
  else pending_.emplace_back(row, col, value);
}

void GlobalSystem::add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& r_in,
                       const Eigen::Ref<const Eigen::MatrixXd>& k_in) {
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
    r_scratch_ = r_in;
    if (tangent) k_scratch_ = k_in;
    for (Eigen::Index i = 0; i + 2 < n; ++i) {
      const GlobalDof d = dofs[static_cast<std::size_t>(i)];
      if (d < 0 || !constraints_.frame_start(d) || dofs[static_cast<std::size_t>(i) + 1] != d + 1 ||
          dofs[static_cast<std::size_t>(i) + 2] != d + 2)
        continue;
      const Mat3& q = *constraints_.frame(d);
      r_scratch_.segment<3>(i) = q.transpose() * r_scratch_.segment<3>(i);
      if (tangent) {
        k_scratch_.middleRows<3>(i) = q.transpose() * k_scratch_.middleRows<3>(i);
        k_scratch_.middleCols<3>(i) = k_scratch_.middleCols<3>(i) * q;
      }
      i += 2;
    }
    r = &r_scratch_;
    k = &k_scratch_;
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
  free_cols_.clear();
  fixed_cols_.clear();
  for (Eigen::Index j = 0; j < n; ++j) {
    const GlobalDof gj = dofs[static_cast<std::size_t>(j)];
    if (gj < 0) continue;
    (constraints_.fixed(gj) ? fixed_cols_ : free_cols_).emplace_back(gj, j);
  }
  std::sort(free_cols_.begin(), free_cols_.end());
  const std::int64_t* cols = matrix_.cols.data();
  for (Eigen::Index i = 0; i < n; ++i) {
    const GlobalDof gi = dofs[static_cast<std::size_t>(i)];
    if (gi < 0 || constraints_.fixed(gi)) continue;
    for (const auto& [gj, j] : fixed_cols_) correction_(gi) += kv(i, j) * prescribed_(gj);
    std::int64_t pos = matrix_.row_ptr[static_cast<std::size_t>(gi)];
    const std::int64_t end = matrix_.row_ptr[static_cast<std::size_t>(gi) + 1];
    for (const auto& [gj, j] : free_cols_) {
      if (pos < end && cols[pos] < gj && (++pos < end && cols[pos] < gj)) pos = std::lower_bound(cols + pos, cols + end, gj) - cols;
      if (pos < end && cols[pos] == gj) matrix_.values[static_cast<std::size_t>(pos)] += kv(i, j);
      else pending_.emplace_back(gi, gj, kv(i, j));
    }
  }
  if (pending_.size() > compact_at_) compact_pending();
}

void GlobalSystem::compact_pending() {
  std::sort(pending_.begin(), pending_.end(), [](const auto& a, const auto& b) {
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
      std::sort(row.begin(), row.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
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
