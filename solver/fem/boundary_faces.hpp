#pragma once
// Boundary faces of a volume mesh, oriented with outward normals (right-hand
// rule on the node order): hex8 -> quad4, tet4 -> tri3, tet10 -> tri6.
#include <array>
#include <cstdint>
#include <vector>

#include "common/mesh_data.hpp"

namespace stentsim::solver::fem {

struct Face {
  CellType type = CellType::triangle;  // quad, triangle or quadratic_triangle
  std::array<std::int64_t, 6> nodes{};
  int count = 0;                       // number of nodes
  std::size_t cell = 0;                // the volume cell it bounds
};

/// Faces that belong to exactly one of the cells with `active[c]` true (all
/// volume cells when `active` is empty).
std::vector<Face> boundary_faces(const MeshData& mesh, const std::vector<bool>& active = {});

}  // namespace stentsim::solver::fem
