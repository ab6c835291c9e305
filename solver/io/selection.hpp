#pragma once
// Geometric and tagged selections of nodes and boundary faces in a body's
// reference mesh, as scenes name them:
//   all: true | plane: {point, normal} | cylinder: {origin, axis, radius[, at]} |
//   box: {min, max} | point_array: {name, value} | cell_array: {name, value}
// (cell_array selects boundary faces that match surface cells of the mesh
// carrying that tag; cylinder's `at` keeps the circle at that axial distance
// from the origin). A face is selected when all its nodes are.
#include <optional>
#include <string>
#include <vector>

#include "common/config.hpp"
#include "common/mesh_data.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/fem/tensor.hpp"

namespace stentsim::solver {

struct Selector {
  enum class Kind { all, plane, cylinder, box, point_array, cell_array } kind = Kind::all;
  Vec3 a = Vec3::Zero(), b = Vec3::UnitZ();  // plane: point, normal; cylinder: origin, axis; box: min, max
  double radius = 0.0;
  std::optional<double> axial;               // cylinder: only nodes at this axial distance from the origin
  double tolerance = -1.0;                   // absolute; < 0: 1e-6 x mesh size
  std::string array;
  double value = 0.0;
  std::string describe() const;
};

/// Reads a selector from `cfg[key]` (a map with exactly one of the kinds).
Selector read_selector(ConfigMap& cfg, const std::string& key);

std::vector<std::size_t> select_nodes(const MeshData& mesh, const Selector& s);
std::vector<fem::Face> select_faces(const MeshData& mesh, const std::vector<fem::Face>& boundary, const Selector& s);

}  // namespace stentsim::solver
