#include "solver/linalg/csr_matrix.hpp"

#include <algorithm>

namespace stentsim::solver {

std::int64_t CsrMatrix::find(std::int64_t row, std::int64_t col) const {
  const auto b = cols.begin() + row_ptr[static_cast<std::size_t>(row)];
  const auto e = cols.begin() + row_ptr[static_cast<std::size_t>(row) + 1];
  const auto it = std::lower_bound(b, e, col);
  return (it != e && *it == col) ? static_cast<std::int64_t>(it - cols.begin()) : -1;
}

Eigen::VectorXd CsrMatrix::multiply(const Eigen::VectorXd& x) const {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(rows);
  for (std::int64_t i = 0; i < rows; ++i)
    for (auto k = row_ptr[static_cast<std::size_t>(i)]; k < row_ptr[static_cast<std::size_t>(i) + 1]; ++k)
      y(i) += values[static_cast<std::size_t>(k)] * x(cols[static_cast<std::size_t>(k)]);
  return y;
}

}  // namespace stentsim::solver
