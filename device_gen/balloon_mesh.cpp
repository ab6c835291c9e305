#include "device_gen/balloon_mesh.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace stentsim::device_gen {

MeshData build_balloon_mesh(const BalloonDesign& d, const DeviceAxis& axis) {
  const int na = d.around(), nl = d.along();
  const double r_in = 0.5 * d.inner_diameter(), r_out = 0.5 * d.outer_diameter;
  MeshData m;
  auto node = [&](int i, int j, int layer) -> std::int64_t {
    return (static_cast<std::int64_t>(j) * na + (i % na)) * 2 + layer;
  };
  DataArray tags{1, {}};
  for (int j = 0; j <= nl; ++j) {
    const AxisFrame f = axis.frame(axis.length() * j / nl);
    for (int i = 0; i < na; ++i) {
      const double phi = 2.0 * std::numbers::pi * i / na;
      const Eigen::Vector3d radial = std::cos(phi) * f.normal + std::sin(phi) * f.binormal;
      for (int layer = 0; layer < 2; ++layer) {
        m.points.push_back(f.position + (layer == 0 ? r_in : r_out) * radial);
        int tag = layer == 0 ? kNodeInner : kNodeOuter;
        if (j == 0) tag |= kNodeProximal;
        if (j == nl) tag |= kNodeDistal;
        tags.values.push_back(tag);
      }
    }
  }
  m.point_data["NodeTag"] = std::move(tags);

  DataArray layer{1, {}}, face_group{1, {}}, parent{1, {}}, parent_face{1, {}}, radial{3, {}}, circ{3, {}}, longi{3, {}};
  auto push3 = [](DataArray& a, const Eigen::Vector3d& v) { a.values.insert(a.values.end(), {v.x(), v.y(), v.z()}); };
  std::vector<std::array<std::int64_t, 8>> hexes;
  for (int j = 0; j < nl; ++j) {
    const AxisFrame f = axis.frame(axis.length() * (j + 0.5) / nl);
    for (int i = 0; i < na; ++i) {
      const std::array<std::int64_t, 8> h = {node(i, j, 0),     node(i, j, 1),     node(i + 1, j, 1),     node(i + 1, j, 0),
                                             node(i, j + 1, 0), node(i, j + 1, 1), node(i + 1, j + 1, 1), node(i + 1, j + 1, 0)};
      hexes.push_back(h);
      m.add_cell(CellType::hexahedron, {h.begin(), h.end()});
      const double phi = 2.0 * std::numbers::pi * (i + 0.5) / na;
      push3(radial, std::cos(phi) * f.normal + std::sin(phi) * f.binormal);
      push3(circ, -std::sin(phi) * f.normal + std::cos(phi) * f.binormal);
      push3(longi, f.tangent);
      layer.values.push_back(tags::balloon_wall);
      face_group.values.push_back(tags::no_face);
      parent.values.push_back(-1);
      parent_face.values.push_back(-1);
    }
  }
  // Tagged faces: VTK hexahedron faces have outward normals for a positive hex.
  static constexpr int kFaces[6][4] = {{0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}};
  auto add_face = [&](std::size_t cell, int face, int group) {
    const auto& h = hexes[cell];
    m.add_cell(CellType::quad, {h[static_cast<std::size_t>(kFaces[face][0])], h[static_cast<std::size_t>(kFaces[face][1])],
                                h[static_cast<std::size_t>(kFaces[face][2])], h[static_cast<std::size_t>(kFaces[face][3])]});
    layer.values.push_back(tags::no_layer);
    face_group.values.push_back(group);
    parent.values.push_back(static_cast<double>(cell));
    parent_face.values.push_back(face);
    for (auto* a : {&radial, &circ, &longi}) a->values.insert(a->values.end(), {0.0, 0.0, 0.0});
  };
  for (std::size_t c = 0; c < hexes.size(); ++c) add_face(c, 0, tags::balloon_inner);
  for (std::size_t c = 0; c < hexes.size(); ++c) add_face(c, 1, tags::balloon_outer);
  for (int i = 0; i < na; ++i) add_face(static_cast<std::size_t>(i), 4, tags::balloon_end_proximal);
  for (int i = 0; i < na; ++i) add_face(static_cast<std::size_t>((nl - 1) * na + i), 5, tags::balloon_end_distal);
  m.cell_data[tags::kLayer] = std::move(layer);
  m.cell_data[tags::kFaceGroup] = std::move(face_group);
  m.cell_data["ParentCell"] = std::move(parent);
  m.cell_data["ParentFace"] = std::move(parent_face);
  m.cell_data["Radial"] = std::move(radial);
  m.cell_data["Circumferential"] = std::move(circ);
  m.cell_data["Longitudinal"] = std::move(longi);
  m.field_text["format"] =
      "stentsim balloon 2: hexahedron cells (Layer 4 = balloon) then tagged quad faces (FaceGroup 5 inner/pressure, "
      "6 outer/contact, 7 proximal end, 8 distal end, as common/mesh_tags.hpp; ParentCell, ParentFace = VTK local face); "
      "NodeTag bits 1 inner 2 outer 4 proximal 8 distal";
  m.field_text["units"] = "mm";
  m.field_text["elements"] = fmt::format("{} around x {} along = {} hex8", na, nl, na * nl);
  m.field_text["design"] = fmt::format("outer diameter {} mm, wall {} mm, length {} mm", d.outer_diameter, d.wall_thickness,
                                       d.length);
  return m;
}

}  // namespace stentsim::device_gen
