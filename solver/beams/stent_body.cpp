#include "solver/beams/stent_body.hpp"

#include "common/error.hpp"

#include <cmath>

namespace stentsim::solver::beams {

namespace {

const DataArray& need(const std::map<std::string, DataArray>& arrays, const std::string& name, int components,
                      std::size_t tuples, const std::string& where, const char* kind) {
  auto it = arrays.find(name);
  if (it == arrays.end())
    throw InputError(where + ": missing " + kind + " array '" + name + "' (stent format 'stentsim stent 1')");
  if (it->second.components != components || it->second.tuples() != tuples)
    throw InputError(where + ": " + kind + " array '" + name + "' must have " + std::to_string(components) +
                     " components and " + std::to_string(tuples) + " tuples");
  return it->second;
}

}  // namespace

StentBeams stent_beams_from_mesh(const MeshData& mesh, double E, double G, const std::string& where) {
  const std::size_t np = mesh.points.size(), nc = mesh.num_cells();
  const DataArray& e1 = need(mesh.point_data, "TriadE1", 3, np, where, "point");
  const DataArray& e2 = need(mesh.point_data, "TriadE2", 3, np, where, "point");
  const DataArray& e3 = need(mesh.point_data, "TriadE3", 3, np, where, "point");
  const DataArray& role = need(mesh.cell_data, "CellRole", 1, nc, where, "cell");
  const DataArray& radius = need(mesh.cell_data, "SectionRadius", 1, nc, where, "cell");
  const DataArray& direction = need(mesh.cell_data, "Direction", 3, nc, where, "cell");

  const auto kind_it = mesh.cell_data.find("MemberKind"), ring_it = mesh.cell_data.find("Ring");
  const bool rings = kind_it != mesh.cell_data.end() && ring_it != mesh.cell_data.end();
  if (rings) need(mesh.cell_data, "MemberKind", 1, nc, where, "cell"), need(mesh.cell_data, "Ring", 1, nc, where, "cell");

  StentBeams s;
  s.body.interpolation = BeamInterpolation::hermite3;
  for (std::size_t i = 0; i < np; ++i) {
    Eigen::Matrix3d T;
    for (int c = 0; c < 3; ++c) T.col(0)[c] = e1.at(i, c), T.col(1)[c] = e2.at(i, c), T.col(2)[c] = e3.at(i, c);
    if ((T.transpose() * T - Eigen::Matrix3d::Identity()).norm() > 1e-8 || T.determinant() < 0)
      throw InputError(where + ": the triad (TriadE1..3) of point " + std::to_string(i) +
                       " is not a right-handed orthonormal frame");
    s.body.nodes.push_back({mesh.points[i], Eigen::Quaterniond(T)});
  }
  double R = -1.0;
  for (std::size_t c = 0; c < nc; ++c) {
    const auto nodes = mesh.cell(c);
    const int r = static_cast<int>(role.at(c));
    if (r == 0) {
      if (mesh.cell_types[c] != CellType::quadratic_edge || nodes.size() != 3)
        throw InputError(where + ": beam cell " + std::to_string(c) +
                         " must be a quadratic edge (end, end, middle node)");
      const double rc = radius.at(c);
      if (!(rc > 0.0)) throw InputError(where + ": SectionRadius of cell " + std::to_string(c) + " must be > 0");
      if (R < 0) R = rc;
      if (std::abs(rc - R) > 1e-12 * R)
        throw InputError(where + ": beams with different SectionRadius are not supported (cell " +
                         std::to_string(c) + ")");
      s.body.elements.push_back({static_cast<int>(nodes[0]), static_cast<int>(nodes[1]), static_cast<int>(nodes[2])});
      // MemberKind 0 = strut (Ring = its ring), 1 = connector (Ring = the gap it bridges).
      if (rings) s.element_ring.push_back(kind_it->second.at(c) == 0 ? static_cast<int>(ring_it->second.at(c)) : -1);
    } else if (r == 1) {
      if (nodes.size() != 2) throw InputError(where + ": joint cell " + std::to_string(c) + " must be a node pair");
      s.joints.push_back({static_cast<int>(nodes[0]), static_cast<int>(nodes[1])});
    } else if (r == 2 || r == 3) {
      if (nodes.size() != 1) throw InputError(where + ": fixation cell " + std::to_string(c) + " must be a vertex");
      const Eigen::Vector3d d(direction.at(c, 0), direction.at(c, 1), direction.at(c, 2));
      if (!(d.norm() > 0)) throw InputError(where + ": fixation cell " + std::to_string(c) + " has no Direction");
      s.fixations.push_back({static_cast<int>(nodes[0]), d.normalized(), r == 3});
    } else {
      throw InputError(where + ": CellRole " + std::to_string(r) + " of cell " + std::to_string(c) +
                       " is not one of 0 (beam), 1 (joint), 2 (radial fixation), 3 (axial fixation)");
    }
  }
  if (s.body.elements.empty()) throw InputError(where + ": no beam cells (CellRole 0)");
  s.body.section = BeamSection::circular(E, G, R);
  s.body.section.validate(where);
  return s;
}

}  // namespace stentsim::solver::beams
