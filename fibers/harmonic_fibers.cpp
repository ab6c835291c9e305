#include "fibers/harmonic_fibers.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"
#include "fibers/laplace_field.hpp"
#include "solver/fem/boundary_faces.hpp"

namespace stentsim::fibers {
namespace {

using Vec3 = Eigen::Vector3d;

void push(DataArray& a, const Vec3& v) { a.values.insert(a.values.end(), {v.x(), v.y(), v.z()}); }
Vec3 get(const DataArray& a, std::size_t c) { return {a.at(c, 0), a.at(c, 1), a.at(c, 2)}; }
double angle_deg(const Vec3& a, const Vec3& b) { return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180.0 / M_PI; }

/// The centerline as chains of points with unit tangents at the points
/// (central differences), so that the tangent interpolated along a segment
/// is continuous from one segment to the next.
struct Centerline {
  std::vector<std::vector<Vec3>> points, tangents;

  explicit Centerline(const MeshData& cl, const std::string& source) {
    for (std::size_t c = 0; c < cl.num_cells(); ++c) {
      const auto t = cl.cell_types[c];
      if (t != CellType::line && t != CellType::polyline) continue;
      std::vector<Vec3> chain;
      for (auto p : cl.cell(c)) {
        const Vec3& x = cl.points[static_cast<std::size_t>(p)];
        if (chain.empty() || (x - chain.back()).norm() > 1e-12) chain.push_back(x);
      }
      // Consecutive two-point line cells that continue each other form one chain.
      if (!points.empty() && t == CellType::line && chain.size() == 2 && (points.back().back() - chain.front()).norm() < 1e-12)
        points.back().push_back(chain.back());
      else if (chain.size() >= 2) points.push_back(std::move(chain));
    }
    if (points.empty()) throw InputError(fmt::format("fibers: centerline {} has no line with two distinct points", source));
    for (const auto& ch : points) {
      std::vector<Vec3> tg(ch.size());
      for (std::size_t i = 0; i < ch.size(); ++i) {
        const Vec3 d = ch[std::min(i + 1, ch.size() - 1)] - ch[i == 0 ? 0 : i - 1];
        tg[i] = d.normalized();
      }
      tangents.push_back(std::move(tg));
    }
  }

  /// Unit tangent at the point of the centerline closest to x.
  Vec3 tangent_at(const Vec3& x) const {
    double best = INFINITY;
    Vec3 t = Vec3::UnitZ();
    for (std::size_t k = 0; k < points.size(); ++k) {
      const auto& ch = points[k];
      for (std::size_t i = 0; i + 1 < ch.size(); ++i) {
        const Vec3 d = ch[i + 1] - ch[i];
        const double s = std::clamp((x - ch[i]).dot(d) / d.squaredNorm(), 0.0, 1.0);
        const double dist = (ch[i] + s * d - x).squaredNorm();
        if (dist < best) {
          best = dist;
          t = ((1 - s) * tangents[k][i] + s * tangents[k][i + 1]).normalized();
        }
      }
    }
    return t;
  }
};

/// Nodes of the faces of each group (all nodes of a face, mid-edge nodes included).
std::map<int, std::set<std::int64_t>> face_group_nodes(const MeshData& mesh, const std::string& source) {
  const auto it = mesh.cell_data.find(tags::kFaceGroup);
  if (it == mesh.cell_data.end())
    throw InputError(fmt::format("fibers: {} has no cell array '{}' (boundary faces tagged endothelium 1, outer_wall 2, "
                                 "proximal_cut 3, distal_cut 4)", source, tags::kFaceGroup));
  std::map<int, std::set<std::int64_t>> nodes;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const auto t = mesh.cell_types[c];
    if (t != CellType::triangle && t != CellType::quadratic_triangle && t != CellType::quad) continue;
    const int g = static_cast<int>(it->second.at(c));
    for (auto p : mesh.cell(c)) nodes[g].insert(p);
  }
  for (int g : {tags::endothelium, tags::outer_wall, tags::proximal_cut, tags::distal_cut})
    if (nodes[g].empty())
      throw InputError(fmt::format("fibers: {} has no boundary faces with {} = {} ({})", source, tags::kFaceGroup, g,
                                   tags::face_group_name(g)));
  return nodes;
}

/// Unit normal at each node of the faces of `groups` (area-weighted mean of
/// the faces' normals; corner nodes of the faces), keyed by mesh node.
std::map<std::int64_t, Vec3> group_node_normals(const MeshData& mesh, std::initializer_list<int> groups) {
  const auto& g = mesh.cell_data.at(tags::kFaceGroup);
  std::map<std::int64_t, Vec3> n;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const auto t = mesh.cell_types[c];
    if (t != CellType::triangle && t != CellType::quadratic_triangle && t != CellType::quad) continue;
    const int grp = static_cast<int>(g.at(c));
    if (std::find(groups.begin(), groups.end(), grp) == groups.end()) continue;
    const auto v = mesh.cell(c);
    const int corners = t == CellType::quad ? 4 : 3;
    auto p = [&](int k) { return mesh.points[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])]; };
    const Vec3 a = t == CellType::quad ? Vec3(0.5 * (p(2) - p(0)).cross(p(3) - p(1))) : Vec3(0.5 * (p(1) - p(0)).cross(p(2) - p(0)));
    for (int k = 0; k < corners; ++k) {
      auto [it, fresh] = n.emplace(v[static_cast<std::size_t>(k)], Vec3::Zero());
      // Faces of one plane share the orientation up to sign: align before summing.
      it->second += it->second.dot(a) < 0 ? Vec3(-a) : a;
    }
  }
  for (auto& [k, v] : n) v.normalize();
  return n;
}

std::map<std::int64_t, double> dirichlet(const std::set<std::int64_t>& zero, const std::set<std::int64_t>& one,
                                         const char* what, const std::string& source) {
  std::map<std::int64_t, double> d;
  for (auto n : zero) d[n] = 0.0;
  for (auto n : one) {
    if (d.count(n))
      throw InputError(fmt::format("fibers: {}: node {} lies on both boundaries of the {} problem", source, n, what));
    d[n] = 1.0;
  }
  return d;
}

/// Polynomial-preserving gradient recovery (after Zhang & Naga 2005) for
/// tet4 cells: at each vertex a least-squares quadratic fit of the nodal
/// values over its edge neighbours (the second ring added when the first has
/// too few nodes for a well-posed fit, e.g. at the boundary), whose gradient
/// at the vertex is the recovered nodal gradient. Exact for quadratic fields,
/// also at boundary vertices where averaging is one-sided.
std::vector<Vec3> nodal_gradients_ppr(const MeshData& mesh, const Eigen::VectorXd& u) {
  const std::size_t np = mesh.points.size();
  std::vector<std::vector<std::int64_t>> adj(np);
  static constexpr int kEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (mesh.cell_types[c] != CellType::tetra) continue;
    const auto n = mesh.cell(c);
    for (const auto& e : kEdges) {
      adj[static_cast<std::size_t>(n[e[0]])].push_back(n[e[1]]);
      adj[static_cast<std::size_t>(n[e[1]])].push_back(n[e[0]]);
    }
  }
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  std::vector<Vec3> nodal(np, Vec3::Zero());
  std::vector<std::int64_t> patch;
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  // A full quadratic in 3D has 10 coefficients; a 1-ring of fewer than 14
  // nodes (boundary vertices) is widened (13 failed on gmsh tubes: 88 deg).
  constexpr std::size_t min_points = 14;
  for (std::size_t i = 0; i < np; ++i) {
    if (adj[i].empty()) continue;
    patch.assign(adj[i].begin(), adj[i].end());
    if (patch.size() < min_points) {
      for (auto j : adj[i])
        for (auto k : adj[static_cast<std::size_t>(j)])
          if (static_cast<std::size_t>(k) != i) patch.push_back(k);
      std::sort(patch.begin(), patch.end());
      patch.erase(std::unique(patch.begin(), patch.end()), patch.end());
    }
    const Vec3 x0 = mesh.points[i];
    double h = 0;
    for (auto j : patch) h = std::max(h, (mesh.points[static_cast<std::size_t>(j)] - x0).norm());
    const auto m = static_cast<Eigen::Index>(patch.size()) + 1;
    A.resize(m, 10);
    b.resize(m);
    auto row = [&](Eigen::Index r, std::int64_t p) {
      const Vec3 d = (mesh.points[static_cast<std::size_t>(p)] - x0) / h;
      A.row(r) << 1, d.x(), d.y(), d.z(), d.x() * d.x(), d.y() * d.y(), d.z() * d.z(), d.x() * d.y(), d.x() * d.z(), d.y() * d.z();
      b(r) = u(p);
    };
    row(0, static_cast<std::int64_t>(i));
    for (std::size_t k = 0; k < patch.size(); ++k) row(static_cast<Eigen::Index>(k) + 1, patch[k]);
    const Eigen::VectorXd coef = A.colPivHouseholderQr().solve(b);
    nodal[i] = coef.segment<3>(1) / h;
  }
  return nodal;
}

/// Per volume cell, the gradient at its centroid: for tet4 cells the mean of
/// the recovered nodal gradients at its corners (the element's own constant
/// gradient is only first-order accurate in direction), for others the
/// element gradient.
std::vector<Vec3> cell_gradients(const MeshData& mesh, const Eigen::VectorXd& u, const std::vector<Vec3>& nodal) {
  std::vector<Vec3> out;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (!is_volume_cell(mesh.cell_types[c])) continue;
    if (mesh.cell_types[c] != CellType::tetra) {
      out.push_back(centroid_gradient(mesh, c, u));
      continue;
    }
    Vec3 g = Vec3::Zero();
    for (auto k : mesh.cell(c)) g += nodal[static_cast<std::size_t>(k)];
    out.push_back(g / 4);
  }
  return out;
}

/// Zero-flux faces of a Laplace problem: the exact gradient is tangent to
/// them, so the recovered gradient at their nodes loses its normal part.
/// `index` maps mesh nodes to the recovery mesh's (corner mesh) or is empty.
void impose_zero_flux(std::vector<Vec3>& nodal, const std::map<std::int64_t, Vec3>& normals, const std::vector<std::int64_t>& index) {
  for (const auto& [node, n] : normals) {
    const std::int64_t i = index.empty() ? node : index[static_cast<std::size_t>(node)];
    if (i < 0) continue;
    auto& g = nodal[static_cast<std::size_t>(i)];
    g -= g.dot(n) * n;
  }
}

/// The tet4 mesh on the corner nodes of the tet10 cells (other volume cells
/// copied), with its points numbered compactly (`full` maps back), and each
/// midside node with its edge's two corners, for the linear Laplace solves.
struct CornerMesh {
  MeshData mesh;
  std::vector<std::int64_t> full;                    // corner-mesh point -> mesh point
  std::vector<std::array<std::int64_t, 3>> midside;  // mesh node, corner a, corner b (mesh numbering)
};

CornerMesh corner_mesh(const MeshData& m) {
  CornerMesh out;
  static constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};  // VTK tet10 midside order
  std::vector<std::int64_t> index(m.points.size(), -1);
  std::vector<char> seen(m.points.size(), 0);
  auto corner = [&](std::int64_t p) {
    auto& i = index[static_cast<std::size_t>(p)];
    if (i < 0) {
      i = static_cast<std::int64_t>(out.full.size());
      out.full.push_back(p);
      out.mesh.points.push_back(m.points[static_cast<std::size_t>(p)]);
    }
    return i;
  };
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    if (!is_volume_cell(m.cell_types[c])) continue;
    const auto n = m.cell(c);
    if (m.cell_types[c] != CellType::quadratic_tetra) {
      std::vector<std::int64_t> k;
      for (auto p : n) k.push_back(corner(p));
      out.mesh.add_cell(m.cell_types[c], k);
      continue;
    }
    out.mesh.add_cell(CellType::tetra, {corner(n[0]), corner(n[1]), corner(n[2]), corner(n[3])});
    for (int e = 0; e < 6; ++e) {
      const auto k = static_cast<std::size_t>(n[static_cast<std::size_t>(4 + e)]);
      if (seen[k]) continue;
      seen[k] = 1;
      out.midside.push_back({n[static_cast<std::size_t>(4 + e)], n[static_cast<std::size_t>(kEdge[e][0])],
                             n[static_cast<std::size_t>(kEdge[e][1])]});
    }
  }
  return out;
}

/// A solved Laplace problem: nodal values on the mesh and, per volume cell,
/// the gradient at its centroid.
struct Field {
  LaplaceSolve solve;
  std::vector<Vec3> grad;
};

/// Solves one Laplace problem, on the corner mesh when given: Dirichlet values
/// on midside nodes are dropped there (their corners carry the same value) and
/// the solution is interpolated linearly along the edges afterwards (exact for
/// the piecewise-linear field on straight edges). Gradients of the tet4
/// fields (the corner mesh, or a tet4 mesh) are recovered (PPR) with the
/// zero-flux condition imposed at the nodes of `zero_flux` (face normals by
/// mesh node); tet10 and hex8 cells use their own centroid gradient.
Field solve_field(const MeshData& mesh, const CornerMesh* corners, const std::map<std::int64_t, double>& d,
                  solver::LinearSolverType solver, const std::map<std::int64_t, Vec3>& zero_flux) {
  Field f;
  if (!corners) {
    f.solve = solve_laplace(mesh, d, solver);
    bool linear = false;
    for (auto t : mesh.cell_types) linear = linear || t == CellType::tetra;
    std::vector<Vec3> nodal;
    if (linear) {
      nodal = nodal_gradients_ppr(mesh, f.solve.u);
      impose_zero_flux(nodal, zero_flux, {});
    }
    f.grad = cell_gradients(mesh, f.solve.u, nodal);
    return f;
  }
  std::vector<std::int64_t> index(mesh.points.size(), -1);
  for (std::size_t i = 0; i < corners->full.size(); ++i) index[static_cast<std::size_t>(corners->full[i])] = static_cast<std::int64_t>(i);
  std::map<std::int64_t, double> dc;
  for (const auto& [node, value] : d)
    if (index[static_cast<std::size_t>(node)] >= 0) dc[index[static_cast<std::size_t>(node)]] = value;
  f.solve = solve_laplace(corners->mesh, dc, solver);
  std::vector<Vec3> nodal = nodal_gradients_ppr(corners->mesh, f.solve.u);
  impose_zero_flux(nodal, zero_flux, index);
  f.grad = cell_gradients(corners->mesh, f.solve.u, nodal);  // corner-mesh cells are the volume cells in order
  Eigen::VectorXd u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh.points.size()));
  for (std::size_t i = 0; i < corners->full.size(); ++i) u(corners->full[i]) = f.solve.u(static_cast<Eigen::Index>(i));
  for (const auto& [node, a, b] : corners->midside) u(node) = 0.5 * (u(a) + u(b));
  // A midside node on a tagged face has both corners on it: its value is the boundary value.
  for (const auto& [node, value] : d) u(node) = value;
  f.solve.u = std::move(u);
  return f;
}

/// How the two Laplace problems were discretized (for fibers.vtu and summary.yaml).
std::string laplace_method(const HarmonicFiberOptions& o, bool quadratic) {
  if (!quadratic) return "Laplace problems on the mesh's own elements, tet4 gradients recovered (PPR, zero-flux faces)";
  if (!o.linear_on_corners) return "tet10: both Laplace problems quadratic";
  if (o.transmural_on_corners) return "tet10: both Laplace problems linear on the corner nodes, gradients recovered (PPR, zero-flux faces)";
  return "tet10: transmural problem quadratic, longitudinal linear on the corner nodes with recovered gradients (PPR, zero-flux faces)";
}

}  // namespace

FiberQuality fiber_quality(const MeshData& f) {
  FiberQuality q;
  q.min_handedness = INFINITY;
  const auto& r = f.cell_data.at("Radial");
  const auto& c = f.cell_data.at("Circumferential");
  const auto& l = f.cell_data.at("Longitudinal");
  const auto& f1 = f.cell_data.at("Fiber1");
  const auto& f2 = f.cell_data.at("Fiber2");
  const auto& layer = f.cell_data.at(tags::kLayer);
  for (std::size_t e = 0; e < f.num_cells(); ++e) {
    Eigen::Matrix3d m;
    m << get(r, e), get(c, e), get(l, e);
    q.orthonormality_error = std::max(q.orthonormality_error, (m.transpose() * m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff());
    q.min_handedness = std::min(q.min_handedness, m.determinant());
  }
  // Face neighbours: cells bounded by the same face are found by the face's
  // sorted corner nodes (the inner faces boundary_faces() drops).
  std::map<std::array<std::int64_t, 4>, std::size_t> seen;
  auto visit = [&](std::array<std::int64_t, 4> key, std::size_t e) {
    std::sort(key.begin(), key.end());
    auto [it, fresh] = seen.emplace(key, e);
    if (fresh) return;
    const std::size_t o = it->second;
    for (const auto* a : {&r, &c, &l})
      q.max_neighbour_frame_angle_deg = std::max(q.max_neighbour_frame_angle_deg, angle_deg(get(*a, e), get(*a, o)));
    if (layer.at(e) == layer.at(o))
      for (const auto* a : {&f1, &f2})
        q.max_neighbour_fiber_angle_deg = std::max(q.max_neighbour_fiber_angle_deg, angle_deg(get(*a, e), get(*a, o)));
  };
  static constexpr int kTetFaces[4][3] = {{0, 1, 2}, {0, 1, 3}, {1, 2, 3}, {0, 2, 3}};
  static constexpr int kHexFaces[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  for (std::size_t e = 0; e < f.num_cells(); ++e) {
    const auto n = f.cell(e);
    if (f.cell_types[e] == CellType::hexahedron) {
      for (const auto& fc : kHexFaces) visit({n[fc[0]], n[fc[1]], n[fc[2]], n[fc[3]]}, e);
    } else {
      for (const auto& fc : kTetFaces) visit({-1, n[fc[0]], n[fc[1]], n[fc[2]]}, e);
    }
  }
  if (f.point_data.count("Transmural")) {
    std::set<std::int64_t> vol(f.connectivity.begin(), f.connectivity.end());
    const auto& t = f.point_data.at("Transmural");
    const auto& lc = f.point_data.at("LongitudinalCoordinate");
    q.transmural_min = q.longitudinal_min = INFINITY;
    q.transmural_max = q.longitudinal_max = -INFINITY;
    for (auto p : vol) {
      const auto i = static_cast<std::size_t>(p);
      q.transmural_min = std::min(q.transmural_min, t.at(i));
      q.transmural_max = std::max(q.transmural_max, t.at(i));
      q.longitudinal_min = std::min(q.longitudinal_min, lc.at(i));
      q.longitudinal_max = std::max(q.longitudinal_max, lc.at(i));
    }
  }
  return q;
}

HarmonicFiberResult harmonic_fibers(const MeshData& mesh, const MeshData& centerline_data, const HarmonicFiberOptions& o,
                                    const std::string& source) {
  if (!(o.centerline_weight >= 0 && o.centerline_weight <= 1))
    throw InputError(fmt::format("fibers: centerline_weight must lie in [0, 1], got {}", o.centerline_weight));
  const auto layer_it = mesh.cell_data.find(tags::kLayer);
  if (layer_it == mesh.cell_data.end()) throw InputError(fmt::format("fibers: {} has no cell array '{}'", source, tags::kLayer));
  std::size_t volume_cells = 0;
  for (auto t : mesh.cell_types) volume_cells += is_volume_cell(t) ? 1 : 0;
  if (volume_cells == 0) throw InputError(fmt::format("fibers: {} has no volume cells (hex8, tet4, tet10)", source));
  const auto groups = face_group_nodes(mesh, source);
  const Centerline centerline(centerline_data, source);

  HarmonicFiberResult res;
  const auto t0 = std::chrono::steady_clock::now();
  bool quadratic = false;
  for (auto t : mesh.cell_types) quadratic = quadratic || t == CellType::quadratic_tetra;
  // tet10: the longitudinal problem (and on request the transmural one) on
  // the corner nodes. The transmural field sets the radial direction, which
  // every other direction is projected against, so it gets the quadratic
  // solve by default; grad l is only blended with the centerline tangent.
  const bool l_on_corners = quadratic && o.linear_on_corners;
  const bool t_on_corners = l_on_corners && o.transmural_on_corners;
  std::optional<CornerMesh> corners;
  if (l_on_corners) corners = corner_mesh(mesh);
  // Zero-flux faces of each problem (the other problem's Dirichlet faces).
  const auto cut_normals = group_node_normals(mesh, {tags::proximal_cut, tags::distal_cut});
  const auto wall_normals = group_node_normals(mesh, {tags::endothelium, tags::outer_wall});
  const Field t = solve_field(mesh, t_on_corners ? &*corners : nullptr,
                              dirichlet(groups.at(tags::endothelium), groups.at(tags::outer_wall), "transmural", source),
                              o.linear_solver, cut_normals);
  const Field l = solve_field(mesh, l_on_corners ? &*corners : nullptr,
                              dirichlet(groups.at(tags::proximal_cut), groups.at(tags::distal_cut), "longitudinal", source),
                              o.linear_solver, wall_normals);
  res.laplace_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  res.transmural_residual = t.solve.relative_residual;
  res.longitudinal_residual = l.solve.relative_residual;
  res.transmural_iterations = t.solve.iterations;
  res.longitudinal_iterations = l.solve.iterations;
  res.transmural_unknowns = static_cast<std::size_t>(t_on_corners ? corners->full.size() : mesh.points.size());
  res.longitudinal_unknowns = static_cast<std::size_t>(l_on_corners ? corners->full.size() : mesh.points.size());

  // Per cell: radial from grad t, the tangent and grad l.
  struct CellFrame {
    Vec3 radial, tangent, grad_l;
  };
  std::vector<CellFrame> frames;
  frames.reserve(volume_cells);
  double orientation = 0;  // sum of tangent . grad l: the centerline may run distal -> proximal
  const std::vector<Vec3>& grad_t = t.grad;
  const std::vector<Vec3>& grad_l = l.grad;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (!is_volume_cell(mesh.cell_types[c])) continue;
    const Vec3 gt = grad_t[frames.size()], gl = grad_l[frames.size()];
    if (!(gt.norm() > 1e-12) || !(gl.norm() > 1e-12))
      throw ComputeError(fmt::format("fibers: {} cell {}: vanishing gradient of the {} coordinate", source, c,
                                     gt.norm() > 1e-12 ? "longitudinal" : "transmural"));
    Vec3 x = Vec3::Zero();
    const auto nodes = mesh.cell(c);
    for (auto p : nodes) x += mesh.points[static_cast<std::size_t>(p)];
    x /= static_cast<double>(nodes.size());
    frames.push_back({gt.normalized(), centerline.tangent_at(x), gl.normalized()});
    orientation += frames.back().tangent.dot(frames.back().grad_l);
  }
  const double sign = orientation < 0 ? -1.0 : 1.0;

  MeshData& out = res.fibers;
  out.points = mesh.points;
  DataArray radial{3, {}}, circ{3, {}}, longi{3, {}}, f1{3, {}}, f2{3, {}}, layer{1, {}}, tc{1, {}}, lc{1, {}};
  std::size_t k = 0;
  double blend_max = 0;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (!is_volume_cell(mesh.cell_types[c])) continue;
    const CellFrame& fr = frames[k++];
    const int lay = static_cast<int>(layer_it->second.at(c));
    const auto a = o.angles.find(lay);
    if (a == o.angles.end())
      throw InputError(fmt::format("fibers: no fiber angle for layer {} ({}, cell {} of {})", lay, tags::layer_name(lay), c, source));
    const Vec3 er = fr.radial;
    auto project = [&](const Vec3& v) { return v - v.dot(er) * er; };
    const Vec3 tang = project(sign * fr.tangent), gl = project(fr.grad_l);
    if (tang.norm() > 1e-8 && gl.norm() > 1e-8) blend_max = std::max(blend_max, angle_deg(tang.normalized(), gl.normalized()));
    const Vec3 blended = project(o.centerline_weight * sign * fr.tangent + (1 - o.centerline_weight) * fr.grad_l);
    if (!(blended.norm() > 1e-8))
      throw ComputeError(fmt::format("fibers: {} cell {}: the longitudinal direction is parallel to grad t", source, c));
    const Vec3 el = blended.normalized();
    const Vec3 ec = el.cross(er);  // e_r x e_c = e_l: right-handed (radial, circumferential, longitudinal)
    push(radial, er);
    push(circ, ec);
    push(longi, el);
    push(f1, std::cos(a->second) * ec + std::sin(a->second) * el);
    push(f2, std::cos(a->second) * ec - std::sin(a->second) * el);
    layer.values.push_back(lay);
    tc.values.push_back(centroid_value(mesh, c, t.solve.u));
    lc.values.push_back(centroid_value(mesh, c, l.solve.u));
    out.add_cell(mesh.cell_types[c], mesh.cell(c));
  }
  out.cell_data["Radial"] = std::move(radial);
  out.cell_data["Circumferential"] = std::move(circ);
  out.cell_data["Longitudinal"] = std::move(longi);
  out.cell_data["Fiber1"] = std::move(f1);
  out.cell_data["Fiber2"] = std::move(f2);
  out.cell_data[tags::kLayer] = std::move(layer);
  out.cell_data["Transmural"] = std::move(tc);
  out.cell_data["LongitudinalCoordinate"] = std::move(lc);
  out.point_data["Transmural"] = {1, std::vector<double>(t.solve.u.data(), t.solve.u.data() + t.solve.u.size())};
  out.point_data["LongitudinalCoordinate"] = {1, std::vector<double>(l.solve.u.data(), l.solve.u.data() + l.solve.u.size())};
  out.field_text["method"] = fmt::format("harmonic lifting (centerline weight {}; {})", o.centerline_weight, laplace_method(o, quadratic));
  res.quality = fiber_quality(out);
  res.quality.tangent_blend_angle_max_deg = blend_max;
  return res;
}

void write_harmonic_fibers(const std::string& artery_vtu, const std::string& centerline_vtp, const HarmonicFiberOptions& o,
                           const std::string& fibers_vtu, Summary& summary) {
  const auto r = harmonic_fibers(read_vtu(artery_vtu), read_vtp(centerline_vtp), o, artery_vtu);
  write_vtu(fibers_vtu, r.fibers);
  const auto& q = r.quality;
  summary.set("fiber_elements", static_cast<double>(r.fibers.num_cells()));
  summary.set("fiber_nodes", static_cast<double>(r.fibers.points.size()));
  for (const auto& [l, phi] : o.angles) summary.set(std::string("fiber_angle_") + tags::layer_name(l), phi * 180 / M_PI, "deg");
  summary.set("frame_orthonormality_error", q.orthonormality_error);
  summary.set("frame_handedness_min", q.min_handedness);
  summary.set("max_neighbour_fiber_angle", q.max_neighbour_fiber_angle_deg, "deg");
  summary.set("max_neighbour_frame_angle", q.max_neighbour_frame_angle_deg, "deg");
  summary.set("transmural_min", q.transmural_min);
  summary.set("transmural_max", q.transmural_max);
  summary.set("longitudinal_coordinate_min", q.longitudinal_min);
  summary.set("longitudinal_coordinate_max", q.longitudinal_max);
  summary.set("tangent_vs_grad_l_angle_max", q.tangent_blend_angle_max_deg, "deg");
  summary.set("laplace_relative_residual", std::max(r.transmural_residual, r.longitudinal_residual));
  summary.set("laplace_time", r.laplace_seconds, "s");
  summary.note("fiber_method", fmt::format("{}, linear solver {}", r.fibers.field_text.at("method"), solver::linear_solver_name(o.linear_solver)));
  summary.set("laplace_transmural_unknowns", static_cast<double>(r.transmural_unknowns));
  summary.set("laplace_longitudinal_unknowns", static_cast<double>(r.longitudinal_unknowns));
  summary.set("laplace_transmural_iterations", r.transmural_iterations);
  summary.set("laplace_longitudinal_iterations", r.longitudinal_iterations);
}

}  // namespace stentsim::fibers
