#pragma once
// Compressed sparse rows with a fixed pattern that grows when new entries
// appear (contact pairs add couplings between steps). Global indices; on
// several MPI ranks each rank holds its own elements' contributions and the
// linear solver sums them.
#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace stentsim::solver {

struct CsrMatrix {
  std::int64_t rows = 0;
  std::vector<std::int64_t> row_ptr{0};
  std::vector<std::int64_t> cols;  // sorted within each row
  std::vector<double> values;
  std::uint64_t pattern_version = 0;  // changes whenever row_ptr/cols change

  std::int64_t nonzeros() const { return static_cast<std::int64_t>(cols.size()); }
  /// Index of (row, col) in values, or -1.
  std::int64_t find(std::int64_t row, std::int64_t col) const;
  /// y = A x.
  Eigen::VectorXd multiply(const Eigen::VectorXd& x) const;
};

}  // namespace stentsim::solver
