#include "solver/linalg/block_split.hpp"

#include <stdexcept>
#include <string>

namespace stentsim::solver {

void split_blocks(const CsrMatrix& a, std::int64_t begin, std::int64_t end, BlockSplit& s) {
  if (begin < 0 || end > a.rows || begin >= end || end - begin == a.rows)
    throw std::invalid_argument("block split: block 1 [" + std::to_string(begin) + ", " + std::to_string(end) + ") of " +
                                std::to_string(a.rows) + " unknowns must be non-empty and leave a second block");
  s.begin = begin;
  s.end = end;
  const std::int64_t n1 = end - begin, n2 = a.rows - n1;
  s.a11.rows = n1;
  s.a21.rows = s.a22.rows = n2;
  for (CsrMatrix* m : {&s.a11, &s.a21, &s.a22}) m->row_ptr.assign(1, 0), m->cols.clear(), m->values.clear();
  s.a11.row_ptr.reserve(static_cast<std::size_t>(n1) + 1);
  s.a21.row_ptr.reserve(static_cast<std::size_t>(n2) + 1);
  s.a22.row_ptr.reserve(static_cast<std::size_t>(n2) + 1);
  // Into the last split's storage: cleared vectors keep their capacity, so after the first
  // solve no fresh pages of a hundred megabytes are faulted in at every linear solve.
  for (std::int64_t i = 0; i < a.rows; ++i) {
    const bool inner_row = i >= begin && i < end;
    for (auto k = a.row_ptr[static_cast<std::size_t>(i)]; k < a.row_ptr[static_cast<std::size_t>(i) + 1]; ++k) {
      const std::int64_t j = a.cols[static_cast<std::size_t>(k)];
      const double v = a.values[static_cast<std::size_t>(k)];
      const bool inner_col = j >= begin && j < end;
      // Columns stay sorted: the map to each block's numbering is monotone.
      if (inner_row && inner_col) s.a11.cols.push_back(j - begin), s.a11.values.push_back(v);
      else if (!inner_row && inner_col) s.a21.cols.push_back(j - begin), s.a21.values.push_back(v);
      else if (!inner_row) s.a22.cols.push_back(s.outer(j)), s.a22.values.push_back(v);
      // (block-1 rows, block-2 columns: A12, which the forward sweep does not use)
    }
    if (inner_row) s.a11.row_ptr.push_back(s.a11.nonzeros());
    else s.a21.row_ptr.push_back(s.a21.nonzeros()), s.a22.row_ptr.push_back(s.a22.nonzeros());
  }
}

CsrMatrix amg_matrix(const CsrMatrix& a11) {
  CsrMatrix m;
  m.rows = a11.rows;
  m.row_ptr.reserve(a11.row_ptr.size());
  for (std::int64_t i = 0; i < a11.rows; ++i) {
    for (auto k = a11.row_ptr[static_cast<std::size_t>(i)]; k < a11.row_ptr[static_cast<std::size_t>(i) + 1]; ++k) {
      const double v = a11.values[static_cast<std::size_t>(k)];
      const std::int64_t j = a11.cols[static_cast<std::size_t>(k)];
      if (v != 0.0 || j == i) m.cols.push_back(j), m.values.push_back(v);
    }
    m.row_ptr.push_back(m.nonzeros());
  }
  return m;
}

bool amg_values_on(const CsrMatrix& a11, const std::vector<std::int64_t>& row_ptr, const std::vector<std::int64_t>& cols,
                   std::vector<double>& values) {
  if (row_ptr.size() != a11.row_ptr.size()) return false;
  values.resize(cols.size());
  for (std::int64_t i = 0; i < a11.rows; ++i) {
    auto k = a11.row_ptr[static_cast<std::size_t>(i)];
    const auto k_end = a11.row_ptr[static_cast<std::size_t>(i) + 1];
    // Both rows are sorted by column: one merge.
    for (auto p = row_ptr[static_cast<std::size_t>(i)]; p < row_ptr[static_cast<std::size_t>(i) + 1]; ++p) {
      const std::int64_t j = cols[static_cast<std::size_t>(p)];
      while (k < k_end && a11.cols[static_cast<std::size_t>(k)] < j) ++k;
      if (k == k_end || a11.cols[static_cast<std::size_t>(k)] != j) return false;
      values[static_cast<std::size_t>(p)] = a11.values[static_cast<std::size_t>(k)];
    }
  }
  return true;
}

}  // namespace stentsim::solver
