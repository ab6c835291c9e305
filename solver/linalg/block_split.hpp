#pragma once
// The 2 × 2 block split of an assembled matrix that gmres_amg_block's
// preconditioner uses: unknowns [begin, end) are block 1 (a solid body,
// smoothed-aggregation AMG), the others block 2 (beams with rotations, a thin
// balloon: factorized directly). The preconditioner is one forward block
// Gauss-Seidel sweep,
//   y1 = AMG(A11)⁻¹ r1,   y2 = A22⁻¹ (r2 − A21 y1),
// a fixed linear operator, so right-preconditioned GMRES converges as for any
// preconditioner; it is good when the contact coupling A21 is weak against
// A22, i.e. when the device is stiffer than the soft wall it presses on
// (Saad, Iterative Methods for Sparse Linear Systems, 2nd ed., §14.3).
#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "solver/linalg/csr_matrix.hpp"

namespace stentsim::solver {

struct BlockSplit {
  std::int64_t begin = 0, end = 0;  // block 1 in the full numbering
  CsrMatrix a11, a21, a22;          // a21: block-2 rows, block-1 columns (local numbering of each block)
  /// Block 2's position of full unknown i outside [begin, end).
  std::int64_t outer(std::int64_t i) const { return i < begin ? i : i - (end - begin); }
  /// Full unknown of block-2 position k.
  std::int64_t full_of_outer(std::int64_t k) const { return k < begin ? k : k + (end - begin); }
};

/// Splits `a` (one rank: the whole matrix) into `out`, reusing its storage. Throws
/// std::invalid_argument when the range is empty or leaves no block 2.
void split_blocks(const CsrMatrix& a, std::int64_t begin, std::int64_t end, BlockSplit& out);

/// The matrix block 1's AMG is built from: A11 without its exact zeros (diagonal kept).
/// Contact pairs reserve entries that stay zero until a point comes within reach; an AMG
/// hierarchy built with them empty cannot take their values later (the coarse operators'
/// graphs lack their products), so the preconditioner's A11 keeps the pattern it was built
/// on: the entries that fill later (contact couplings of surface nodes that share no
/// element) act through GMRES's operator, not through the V-cycle.
CsrMatrix amg_matrix(const CsrMatrix& a11);
/// A11's values at the positions of an earlier amg_matrix's pattern (row_ptr, cols), in
/// that pattern's order. False when that pattern has a position `a11` lacks (another model);
/// `values` is then undefined.
bool amg_values_on(const CsrMatrix& a11, const std::vector<std::int64_t>& row_ptr, const std::vector<std::int64_t>& cols,
                   std::vector<double>& values);

}  // namespace stentsim::solver
