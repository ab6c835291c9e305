#include "fibers/tagged_tube.hpp"

#include <cmath>

#include "common/mesh_tags.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"

namespace stentsim::fibers {
namespace {
using Vec3 = Eigen::Vector3d;

Vec3 bend(const TaggedTubeSpec& s, const Vec3& p) {
  if (s.bend_radius <= 0) return p;
  const double r = s.bend_radius, a = p.z() / r;
  const Vec3 c(r * (1 - std::cos(a)), 0, r * std::sin(a));
  const Vec3 e1(std::cos(a), 0, -std::sin(a));  // toward the centre of curvature
  return c + p.x() * e1 + p.y() * Vec3::UnitY();
}
}  // namespace

MeshData tagged_tube(const TaggedTubeSpec& s) {
  MeshData m = solver::hex8_to_tet4(solver::ring_sector_hex8(s.inner_radius, s.outer_radius, 2 * M_PI, s.length,
                                                              s.elements_radial, s.elements_around, s.elements_along));
  if (s.quadratic) m = solver::tet4_to_tet10(m);
  m.point_data.clear();
  const double mid = 0.5 * (s.inner_radius + s.outer_radius);
  DataArray layer{1, {}}, group{1, {}};
  auto centroid = [&](const std::vector<std::int64_t>& nodes) {
    Vec3 x = Vec3::Zero();
    for (auto n : nodes) x += m.points[static_cast<std::size_t>(n)];
    return Vec3(x / static_cast<double>(nodes.size()));
  };
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    const Vec3 x = centroid(m.cell(c));
    layer.values.push_back(std::hypot(x.x(), x.y()) < mid ? tags::media : tags::adventitia);
    group.values.push_back(tags::no_face);
  }
  for (const auto& f : solver::fem::boundary_faces(m)) {
    const std::vector<std::int64_t> nodes(f.nodes.begin(), f.nodes.begin() + f.count);
    const Vec3 x = centroid(nodes);
    const int g = x.z() < 1e-9 ? tags::proximal_cut
                  : x.z() > s.length - 1e-9 ? tags::distal_cut
                  : std::hypot(x.x(), x.y()) < mid ? tags::endothelium : tags::outer_wall;
    m.add_cell(f.type, nodes);
    layer.values.push_back(tags::no_layer);
    group.values.push_back(g);
  }
  m.cell_data[tags::kLayer] = std::move(layer);
  m.cell_data[tags::kFaceGroup] = std::move(group);
  for (auto& p : m.points) p = bend(s, p);
  return m;
}

MeshData tagged_tube_axis(const TaggedTubeSpec& s, double extend, int segments) {
  MeshData c;
  std::vector<std::int64_t> ids;
  for (int i = 0; i <= segments; ++i) {
    c.points.push_back(bend(s, Vec3(0, 0, -extend + (s.length + 2 * extend) * i / segments)));
    ids.push_back(i);
  }
  c.add_cell(CellType::polyline, ids);
  return c;
}

}  // namespace stentsim::fibers
