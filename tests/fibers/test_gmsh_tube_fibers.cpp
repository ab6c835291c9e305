// Harmonic-lifting fibers on unstructured gmsh tubes (tet4 and tet10), the
// kind of mesh the meshing stage hands over: frames against the analytic
// tube fibers, and the Laplace solutions' boundary values and range.
#include <gmsh.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "common/mesh_tags.hpp"
#include "fibers/analytic_tube_fibers.hpp"
#include "fibers/harmonic_fibers.hpp"
#include "fibers/tagged_tube.hpp"
#include "solver/fem/boundary_faces.hpp"

using namespace stentsim;
using Vec3 = Eigen::Vector3d;

namespace {
constexpr double kRi = 0.8, kRo = 1.4, kLength = 3.0;

/// A hollow cylinder meshed by gmsh (OCC boolean cut), tagged like artery.vtu.
MeshData gmsh_tube(bool quadratic, double size) {
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::model::add("tube");
  const int outer = gmsh::model::occ::addCylinder(0, 0, 0, 0, 0, kLength, kRo);
  const int inner = gmsh::model::occ::addCylinder(0, 0, 0, 0, 0, kLength, kRi);
  std::vector<std::pair<int, int>> out;
  std::vector<std::vector<std::pair<int, int>>> map;
  gmsh::model::occ::cut({{3, outer}}, {{3, inner}}, out, map);
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", size);
  gmsh::option::setNumber("Mesh.MeshSizeMin", 0.5 * size);
  gmsh::model::mesh::generate(3);
  if (quadratic) gmsh::model::mesh::setOrder(2);
  std::vector<std::size_t> node_tags;
  std::vector<double> xyz, param;
  gmsh::model::mesh::getNodes(node_tags, xyz, param);
  MeshData m;
  std::map<std::size_t, std::int64_t> index;
  for (std::size_t i = 0; i < node_tags.size(); ++i) {
    index[node_tags[i]] = static_cast<std::int64_t>(i);
    m.points.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  }
  std::vector<std::size_t> elem_tags, elem_nodes;
  const int type = quadratic ? 11 : 4;  // gmsh tet10 / tet4
  gmsh::model::mesh::getElementsByType(type, elem_tags, elem_nodes);
  gmsh::finalize();
  const int n = quadratic ? 10 : 4;
  for (std::size_t e = 0; e < elem_tags.size(); ++e) {
    std::vector<std::int64_t> c(static_cast<std::size_t>(n));
    for (int a = 0; a < n; ++a) c[static_cast<std::size_t>(a)] = index.at(elem_nodes[e * n + static_cast<std::size_t>(a)]);
    if (quadratic) std::swap(c[8], c[9]);  // gmsh edge order (.., 2-3, 1-3) -> VTK (.., 1-3, 2-3)
    m.add_cell(quadratic ? CellType::quadratic_tetra : CellType::tetra, c);
  }
  DataArray layer{1, {}}, group{1, {}};
  const double mid = 0.5 * (kRi + kRo);
  auto centroid = [&](const std::vector<std::int64_t>& nodes) {
    Vec3 x = Vec3::Zero();
    for (auto k : nodes) x += m.points[static_cast<std::size_t>(k)];
    return Vec3(x / static_cast<double>(nodes.size()));
  };
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    const Vec3 x = centroid(m.cell(c));
    layer.values.push_back(std::hypot(x.x(), x.y()) < mid ? tags::media : tags::adventitia);
    group.values.push_back(0);
  }
  for (const auto& f : solver::fem::boundary_faces(m)) {
    const std::vector<std::int64_t> nodes(f.nodes.begin(), f.nodes.begin() + f.count);
    const Vec3 x = centroid(nodes);
    const int g = x.z() < 1e-6 ? tags::proximal_cut : x.z() > kLength - 1e-6 ? tags::distal_cut
                  : std::hypot(x.x(), x.y()) < mid ? tags::endothelium : tags::outer_wall;
    m.add_cell(f.type, nodes);
    layer.values.push_back(0);
    group.values.push_back(g);
  }
  m.cell_data[tags::kLayer] = layer;
  m.cell_data[tags::kFaceGroup] = group;
  return m;
}

double deg(const Vec3& a, const Vec3& b) { return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180 / M_PI; }

/// `all_corners`: tet10 with both Laplace problems on the corner nodes (the
/// fast option); otherwise the defaults (tet10: t quadratic, l on the corners).
void check(bool quadratic, bool all_corners = false) {
  const MeshData mesh = gmsh_tube(quadratic, quadratic ? 0.2 : 0.15);
  const fibers::LayerAngles angles{{tags::media, 0.0}, {tags::adventitia, 40 * M_PI / 180}};
  fibers::HarmonicFiberOptions o;
  o.angles = angles;
  if (!quadratic) o.linear_solver = solver::LinearSolverType::direct;  // the three solver paths: direct, default AMG, ILU
  if (all_corners) o.transmural_on_corners = true, o.linear_solver = solver::LinearSolverType::gmres_ilu;
  fibers::TaggedTubeSpec axis;
  axis.length = kLength;
  const auto r = fibers::harmonic_fibers(mesh, fibers::tagged_tube_axis(axis), o);
  const MeshData a = fibers::tube_fibers(mesh, angles);
  ASSERT_EQ(a.num_cells(), r.fibers.num_cells());
  double mean = 0, worst = 0;
  std::size_t n = 0;
  for (std::size_t c = 0; c < a.num_cells(); ++c)
    for (const char* name : {"Radial", "Circumferential", "Longitudinal", "Fiber1", "Fiber2"}) {
      const auto& u = a.cell_data.at(name);
      const auto& v = r.fibers.cell_data.at(name);
      const double d = deg(Vec3(u.at(c, 0), u.at(c, 1), u.at(c, 2)), Vec3(v.at(c, 0), v.at(c, 1), v.at(c, 2)));
      mean += d, worst = std::max(worst, d), ++n;
    }
  mean /= static_cast<double>(n);
  const auto& q = r.quality;
  std::printf("gmsh %s tube (%zu nodes, %zu cells): mean angle error %.3f deg, max %.3f deg; t in [%.3g, %.3g], "
              "l in [%.3g, %.3g]; neighbour fiber angle max %.2f deg; Laplace %.2f s (%zu + %zu unknowns)\n",
              quadratic ? (all_corners ? "tet10 (both problems on the corners)" : "tet10 (defaults)") : "tet4", mesh.points.size(),
              a.num_cells(), mean, worst, q.transmural_min, q.transmural_max, q.longitudinal_min, q.longitudinal_max,
              q.max_neighbour_fiber_angle_deg, r.laplace_seconds, r.transmural_unknowns, r.longitudinal_unknowns);
  // Issue 5's bounds. Measured: tet4 0.124 / 0.711 deg, tet10 defaults 0.062 /
  // 0.477, tet10 all on corners 0.195 / 1.409 (before the recovery with the
  // zero-flux condition the corner solves had 0.354 / 2.374, the maximum at
  // the endothelium-cut edge: grad t tilted along the axis).
  EXPECT_LT(mean, 0.5);
  EXPECT_LT(worst, 2.0);
  if (quadratic) {
    EXPECT_EQ(r.transmural_unknowns, all_corners ? r.longitudinal_unknowns : mesh.points.size());
    EXPECT_LT(r.longitudinal_unknowns, mesh.points.size() / 4);  // corner nodes only
  }
  EXPECT_LT(q.orthonormality_error, 1e-12);
  EXPECT_NEAR(q.min_handedness, 1, 1e-12);
  // tet4: the discrete maximum principle up to round-off is not guaranteed on
  // an unstructured mesh with obtuse dihedral angles; tet10: none in general.
  // We check the range overshoots by less than 1 % (tet4, linear fields) and
  // 2 % (a quadratic t).
  const double tol = quadratic && !all_corners ? 0.02 : 0.01;
  EXPECT_GE(q.transmural_min, -tol);
  EXPECT_LE(q.transmural_max, 1 + tol);
  EXPECT_GE(q.longitudinal_min, -tol);
  EXPECT_LE(q.longitudinal_max, 1 + tol);
}
}  // namespace

TEST(GmshTubeFibers, Tet4MatchesAnalytic) { check(false); }
// The stage's default on tet10 meshes: t quadratic, l on the corner nodes.
TEST(GmshTubeFibers, Tet10DefaultsMatchAnalytic) { check(true); }
// The fast option: both problems on the corner nodes (the tet4 mesh of the
// same vertices) with recovered gradients, within the same bounds here.
TEST(GmshTubeFibers, Tet10AllCornerSolvesMatchAnalytic) { check(true, true); }
