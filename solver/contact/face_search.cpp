#include "solver/contact/face_search.hpp"

#include <algorithm>
#include <cmath>

namespace stentsim::solver::contact {

void FaceSearch::build(const ContactSurface& s, double margin) {
  margin_ = margin;
  boxes_.assign(s.faces().size(), Eigen::AlignedBox3d());
  Eigen::AlignedBox3d all;
  double size = 0.0;
  for (std::size_t f = 0; f < s.faces().size(); ++f) {
    const SurfaceFace& face = s.faces()[f];
    for (int k = 0; k < face.count; ++k) boxes_[f].extend(s.x(face.node[k]));
    size += boxes_[f].diagonal().norm();
    boxes_[f].min().array() -= margin;
    boxes_[f].max().array() += margin;
    all.extend(boxes_[f]);
  }
  // Bins about the size of a face (plus the margin), at most ~2 million of them.
  h_ = std::max(size / static_cast<double>(std::max<std::size_t>(boxes_.size(), 1)) + margin, 1e-9);
  const Vec3 extent = all.diagonal();
  for (;;) {
    for (int a = 0; a < 3; ++a) dims_[a] = std::max(1, static_cast<int>(std::ceil(extent[a] / h_)));
    if (static_cast<double>(dims_.prod()) <= 2e6) break;
    h_ *= 1.5;
  }
  origin_ = all.min();
  std::vector<int> count(static_cast<std::size_t>(dims_.prod()) + 1, 0);
  auto for_bins = [&](const Eigen::AlignedBox3d& b, auto&& f) {
    const Eigen::Array3i lo = cell_of(b.min()), hi = cell_of(b.max());
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) f((k * dims_[1] + j) * dims_[0] + i);
  };
  for (const auto& b : boxes_) for_bins(b, [&](int bin) { ++count[static_cast<std::size_t>(bin) + 1]; });
  for (std::size_t b = 1; b < count.size(); ++b) count[b] += count[b - 1];
  start_ = count;
  items_.assign(static_cast<std::size_t>(count.back()), 0);
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (std::size_t f = 0; f < boxes_.size(); ++f)
    for_bins(boxes_[f], [&](int bin) { items_[static_cast<std::size_t>(fill[static_cast<std::size_t>(bin)]++)] = static_cast<int>(f); });
}

Eigen::Array3i FaceSearch::cell_of(const Vec3& x) const {
  Eigen::Array3i c;
  for (int a = 0; a < 3; ++a) c[a] = std::clamp(static_cast<int>(std::floor((x[a] - origin_[a]) / h_)), 0, dims_[a] - 1);
  return c;
}

void FaceSearch::query(const Vec3& lo, const Vec3& hi, std::vector<int>& out) const {
  out.clear();
  const Eigen::AlignedBox3d q(lo, hi);
  const Eigen::Array3i a = cell_of(lo), b = cell_of(hi);
  for (int k = a[2]; k <= b[2]; ++k)
    for (int j = a[1]; j <= b[1]; ++j)
      for (int i = a[0]; i <= b[0]; ++i) {
        const int bin = (k * dims_[1] + j) * dims_[0] + i;
        for (int p = start_[static_cast<std::size_t>(bin)]; p < start_[static_cast<std::size_t>(bin) + 1]; ++p) {
          const int f = items_[static_cast<std::size_t>(p)];
          if (boxes_[static_cast<std::size_t>(f)].intersects(q)) out.push_back(f);
        }
      }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace stentsim::solver::contact
