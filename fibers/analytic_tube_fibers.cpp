#include "fibers/analytic_tube_fibers.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"

namespace stentsim::fibers {
namespace {
bool is_volume(CellType t) {
  return t == CellType::tetra || t == CellType::hexahedron || t == CellType::quadratic_tetra;
}
void push(DataArray& a, const Eigen::Vector3d& v) { a.values.insert(a.values.end(), {v.x(), v.y(), v.z()}); }
}  // namespace

MeshData tube_fibers(const MeshData& mesh, const LayerAngles& angles) {
  MeshData out;
  out.points = mesh.points;
  const auto layer_it = mesh.cell_data.find(tags::kLayer);
  if (layer_it == mesh.cell_data.end()) throw InputError("fibers: the mesh has no cell array 'Layer'");
  DataArray radial{3, {}}, circ{3, {}}, longi{3, {}}, f1{3, {}}, f2{3, {}}, layer{1, {}}, transmural{1, {}};
  // The transmural coordinate the harmonic lifting computes (Laplace with t = 0
  // on the endothelium, 1 on the outer wall) is, on a straight annulus,
  // t = ln(r/r_i)/ln(r_o/r_i); r_i, r_o are the mesh's smallest and largest radii.
  double r_i = INFINITY, r_o = 0.0;
  for (const auto& p : mesh.points) {
    const double r = std::hypot(p.x(), p.y());
    r_i = std::min(r_i, r);
    r_o = std::max(r_o, r);
  }
  if (!(r_i > 0.0 && r_o > r_i))
    throw InputError(fmt::format("fibers: the mesh is not a tube around the z axis (radii {} to {})", r_i, r_o));
  const auto t_of = [&](double r) { return std::log(r / r_i) / std::log(r_o / r_i); };
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (!is_volume(mesh.cell_types[c])) continue;
    const auto nodes = mesh.cell(c);
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (auto n : nodes) x += mesh.points[static_cast<std::size_t>(n)];
    x /= static_cast<double>(nodes.size());
    const int l = static_cast<int>(layer_it->second.at(c));
    auto a = angles.find(l);
    if (a == angles.end()) throw InputError(fmt::format("fibers: no fiber angle for layer {} (cell {})", tags::layer_name(l), c));
    const Eigen::Vector3d ez(0, 0, 1);
    Eigen::Vector3d er(x.x(), x.y(), 0);
    er.normalize();
    const Eigen::Vector3d et = ez.cross(er);  // right-handed (e_r, e_theta, e_z)
    push(radial, er);
    push(circ, et);
    push(longi, ez);
    push(f1, std::cos(a->second) * et + std::sin(a->second) * ez);
    push(f2, std::cos(a->second) * et - std::sin(a->second) * ez);
    layer.values.push_back(l);
    transmural.values.push_back(t_of(std::hypot(x.x(), x.y())));
    out.add_cell(mesh.cell_types[c], nodes);
  }
  out.cell_data["Radial"] = std::move(radial);
  out.cell_data["Circumferential"] = std::move(circ);
  out.cell_data["Longitudinal"] = std::move(longi);
  out.cell_data["Fiber1"] = std::move(f1);
  out.cell_data["Fiber2"] = std::move(f2);
  out.cell_data[tags::kLayer] = std::move(layer);
  out.cell_data["Transmural"] = std::move(transmural);
  DataArray tp{1, {}};
  for (const auto& p : mesh.points) tp.values.push_back(t_of(std::hypot(p.x(), p.y())));
  out.point_data["Transmural"] = std::move(tp);
  out.field_text["method"] = "analytic straight tube (axis +z)";
  return out;
}

void write_tube_fibers(const std::string& artery_vtu, const LayerAngles& angles, const std::string& fibers_vtu,
                       Summary& summary) {
  const MeshData f = tube_fibers(read_vtu(artery_vtu), angles);
  write_vtu(fibers_vtu, f);
  summary.set("fiber_elements", static_cast<double>(f.num_cells()));
  for (const auto& [l, phi] : angles) summary.set(std::string("fiber_angle_") + tags::layer_name(l), phi * 180 / M_PI, "deg");
  summary.note("fiber_method", "analytic straight tube");
}

}  // namespace stentsim::fibers
