#include "solver/fem/face_orientation.hpp"

#include <Eigen/Geometry>

namespace stentsim::solver::fem {

double face_side(const MeshData& mesh, const Face& face, const std::function<Eigen::Vector3d(std::size_t)>& position) {
  const auto at = [&](int i) { return position(static_cast<std::size_t>(face.nodes[static_cast<std::size_t>(i)])); };
  // Quadratic triangles keep their corners first (VTK order); a quad's normal
  // is the cross product of its diagonals.
  const bool quad = face.type == CellType::quad;
  const int corners = quad ? 4 : 3;
  const Eigen::Vector3d n = quad ? Eigen::Vector3d((at(2) - at(0)).cross(at(3) - at(1)))
                                 : Eigen::Vector3d((at(1) - at(0)).cross(at(2) - at(0)));
  Eigen::Vector3d c_face = Eigen::Vector3d::Zero();
  for (int i = 0; i < corners; ++i) c_face += at(i);
  c_face /= corners;
  const auto begin = static_cast<std::size_t>(mesh.cell_offsets[face.cell]);
  const auto end = static_cast<std::size_t>(mesh.cell_offsets[face.cell + 1]);
  Eigen::Vector3d c_cell = Eigen::Vector3d::Zero();
  for (std::size_t k = begin; k < end; ++k) c_cell += position(static_cast<std::size_t>(mesh.connectivity[k]));
  c_cell /= static_cast<double>(end - begin);
  return n.dot(c_cell - c_face);
}

}  // namespace stentsim::solver::fem
