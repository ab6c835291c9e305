#include "common/mesh_data.hpp"

namespace stentsim {

int nodes_per_cell(CellType t) {
  switch (t) {
    case CellType::vertex: return 1;
    case CellType::line: return 2;
    case CellType::polyline: return 0;
    case CellType::triangle: return 3;
    case CellType::quad: return 4;
    case CellType::tetra: return 4;
    case CellType::hexahedron: return 8;
    case CellType::quadratic_edge: return 3;
    case CellType::quadratic_triangle: return 6;
    case CellType::quadratic_tetra: return 10;
  }
  return 0;
}

void MeshData::add_cell(CellType t, const std::vector<std::int64_t>& nodes) {
  cell_types.push_back(t);
  connectivity.insert(connectivity.end(), nodes.begin(), nodes.end());
  cell_offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
}

std::vector<std::int64_t> MeshData::cell(std::size_t i) const {
  return {connectivity.begin() + cell_offsets[i], connectivity.begin() + cell_offsets[i + 1]};
}

}  // namespace stentsim
