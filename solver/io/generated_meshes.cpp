#include "solver/io/generated_meshes.hpp"

#include <cmath>
#include <map>
#include <stdexcept>

#include <Eigen/Geometry>

namespace stentsim::solver {
namespace {

double tet_volume(const MeshData& m, const std::vector<std::int64_t>& t) {
  const auto& a = m.points[static_cast<std::size_t>(t[0])];
  return (m.points[static_cast<std::size_t>(t[1])] - a)
      .cross(m.points[static_cast<std::size_t>(t[2])] - a)
      .dot(m.points[static_cast<std::size_t>(t[3])] - a);
}

MeshData structured_hex(int nx, int ny, int nz, const auto& position) {
  if (nx < 1 || ny < 1 || nz < 1) throw std::invalid_argument("structured mesh needs at least one element per direction");
  MeshData m;
  auto id = [&](int i, int j, int k) { return static_cast<std::int64_t>(i + (nx + 1) * (j + (ny + 1) * k)); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) m.points.push_back(position(i, j, k));
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        m.add_cell(CellType::hexahedron, {id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                                          id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)});
  return m;
}

}  // namespace

MeshData box_hex8(int nx, int ny, int nz, double lx, double ly, double lz) {
  return structured_hex(nx, ny, nz, [&](int i, int j, int k) {
    return Eigen::Vector3d(lx * i / nx, ly * j / ny, lz * k / nz);
  });
}

MeshData ring_sector_hex8(double ri, double ro, double angle_rad, double height, int nr, int nt, int nz) {
  // i runs through the wall (r), j around (theta), k along z: right-handed
  // node order (positive Jacobian).
  MeshData m = structured_hex(nr, nt, nz, [&](int i, int j, int k) {
    const double r = ri + (ro - ri) * i / nr, t = angle_rad * j / nt;
    return Eigen::Vector3d(r * std::cos(t), r * std::sin(t), height * k / nz);
  });
  // A full ring: the last column of nodes (theta = 2 pi) is the first one.
  if (angle_rad >= 2 * M_PI - 1e-12) {
    const int per_layer = (nr + 1) * (nt + 1);
    std::vector<std::int64_t> remap(m.points.size());
    std::vector<Eigen::Vector3d> kept;
    for (std::size_t id = 0; id < m.points.size(); ++id) {
      const int local = static_cast<int>(id) % per_layer, j = local / (nr + 1);
      if (j == nt) continue;
      remap[id] = static_cast<std::int64_t>(kept.size());
      kept.push_back(m.points[id]);
    }
    for (std::size_t id = 0; id < m.points.size(); ++id) {
      const int local = static_cast<int>(id) % per_layer, j = local / (nr + 1);
      if (j == nt) remap[id] = remap[id - static_cast<std::size_t>(nt * (nr + 1))];
    }
    for (auto& c : m.connectivity) c = remap[static_cast<std::size_t>(c)];
    m.points = std::move(kept);
  }
  DataArray radius;
  for (const auto& p : m.points) radius.values.push_back(std::hypot(p.x(), p.y()));
  m.point_data["ReferenceRadius"] = radius;
  return m;
}

MeshData hex8_to_tet4(const MeshData& hex) {
  static const int kSplit[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
  MeshData t;
  t.points = hex.points;
  for (std::size_t c = 0; c < hex.num_cells(); ++c) {
    if (hex.cell_types[c] != CellType::hexahedron) throw std::invalid_argument("hex8_to_tet4: not a hex8 mesh");
    const auto h = hex.cell(c);
    for (const auto& s : kSplit) {
      std::vector<std::int64_t> tet{h[static_cast<std::size_t>(s[0])], h[static_cast<std::size_t>(s[1])],
                                    h[static_cast<std::size_t>(s[2])], h[static_cast<std::size_t>(s[3])]};
      if (tet_volume(t, tet) < 0) std::swap(tet[1], tet[2]);
      t.add_cell(CellType::tetra, tet);
    }
  }
  return t;
}

namespace {

MeshData tet4_to_tet10_with(const MeshData& tet, const auto& midpoint) {
  static const int kEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  MeshData m;
  m.points = tet.points;
  std::map<std::pair<std::int64_t, std::int64_t>, std::int64_t> mid;
  for (std::size_t c = 0; c < tet.num_cells(); ++c) {
    if (tet.cell_types[c] != CellType::tetra) throw std::invalid_argument("tet4_to_tet10: not a tet4 mesh");
    auto conn = tet.cell(c);
    for (const auto& e : kEdges) {
      auto a = conn[static_cast<std::size_t>(e[0])], b = conn[static_cast<std::size_t>(e[1])];
      const auto key = std::minmax(a, b);
      auto [it, inserted] = mid.try_emplace({key.first, key.second}, static_cast<std::int64_t>(m.points.size()));
      if (inserted) m.points.push_back(midpoint(m.points[static_cast<std::size_t>(a)], m.points[static_cast<std::size_t>(b)]));
      conn.push_back(it->second);
    }
    m.add_cell(CellType::quadratic_tetra, conn);
  }
  m.cell_data = tet.cell_data;
  return m;
}

}  // namespace

MeshData tet4_to_tet10(const MeshData& tet) {
  return tet4_to_tet10_with(tet, [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return Eigen::Vector3d(0.5 * (a + b)); });
}

MeshData tet4_to_tet10_cylindrical(const MeshData& tet) {
  return tet4_to_tet10_with(tet, [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const double ra = std::hypot(a.x(), a.y()), rb = std::hypot(b.x(), b.y());
    if (ra == 0 || rb == 0) return Eigen::Vector3d(0.5 * (a + b));  // on the axis: no angle
    const double ta = std::atan2(a.y(), a.x());
    const double dt = std::remainder(std::atan2(b.y(), b.x()) - ta, 2 * M_PI);  // the short way round
    const double r = 0.5 * (ra + rb), t = ta + 0.5 * dt;
    return Eigen::Vector3d(r * std::cos(t), r * std::sin(t), 0.5 * (a.z() + b.z()));
  });
}

}  // namespace stentsim::solver
