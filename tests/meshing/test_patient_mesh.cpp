// Patient wall mesh on an analytic straight tube: sections, conforming layers,
// tags and outward faces, layer volumes vs the analytic ones, quality, errors.
#include <gtest/gtest.h>

#include <cstdio>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <tuple>
#include <map>
#include <numbers>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"
#include "meshing/patient_mesh.hpp"

using namespace stentsim;
using Eigen::Vector3d;

namespace {

constexpr double kL = 4.0, kRl = 1.0, kRw = 2.0;

MeshData tube_surface(double r, int nt = 96, int nz = 40) {
  MeshData m;
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i < nt; ++i) {
      const double th = 2 * std::numbers::pi * i / nt;
      m.points.emplace_back(r * std::cos(th), r * std::sin(th), kL * j / nz);
    }
  auto id = [&](int i, int j) { return std::int64_t(j * nt + (i % nt)); };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nt; ++i) {
      m.add_cell(CellType::triangle, {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.add_cell(CellType::triangle, {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

MeshData tube_centerline(bool with_normals = true) {
  MeshData c;
  const int n = 41;
  DataArray ptn{3, {}};
  for (int j = 0; j < n; ++j) {
    c.points.emplace_back(0, 0, kL * j / (n - 1));
    ptn.values.insert(ptn.values.end(), {1, 0, 0});
  }
  std::vector<std::int64_t> ids(n);
  for (int j = 0; j < n; ++j) ids[std::size_t(j)] = j;
  c.add_cell(CellType::polyline, ids);
  if (with_normals) c.point_data["ParallelTransportNormals"] = ptn;
  return c;
}

meshing::PatientMeshOptions coarse(const std::string& element) {
  meshing::PatientMeshOptions o;
  o.element = element;
  o.size = 0.4;
  o.station_spacing = 0.5;
  return o;
}

double tet_volume(const MeshData& m, std::size_t c) {
  auto n = m.cell(c);
  const Vector3d a = m.points[std::size_t(n[0])], b = m.points[std::size_t(n[1])], cc = m.points[std::size_t(n[2])],
                 d = m.points[std::size_t(n[3])];
  return (b - a).dot((cc - a).cross(d - a)) / 6;
}

struct Meshed {
  MeshData mesh;
  meshing::WallSections w;
};

const Meshed& tet4_tube() {
  static const Meshed r = [] {
    const auto o = coarse("tet4");
    Meshed x;
    x.w = meshing::wall_sections(tube_surface(kRl), tube_surface(kRw), tube_centerline(), o);
    x.mesh = meshing::mesh_wall_sections(x.w, o, std::filesystem::temp_directory_path() / "stentsim_test_tube.msh");
    return x;
  }();
  return r;
}

}  // namespace

TEST(PatientMeshSections, StraightTubeRadiiFollowTheThicknessRule) {
  const auto o = coarse("tet4");
  const auto w = meshing::wall_sections(tube_surface(kRl), tube_surface(kRw), tube_centerline(), o);
  ASSERT_EQ(w.layers, (std::vector<int>{tags::intima, tags::media, tags::adventitia}));
  const double D = 2 * kRw;  // faceted surfaces: radii within the chord error of 96 facets
  for (std::size_t s = 0; s < w.origin.size(); ++s)
    for (std::size_t i = 0; i < w.radius[s][0].size(); ++i) {
      EXPECT_NEAR(w.radius[s][0][i], kRl, 1e-3 * kRl);
      EXPECT_NEAR(w.radius[s][3][i], kRw, 1e-3 * kRw);
      EXPECT_NEAR(w.radius[s][2][i], kRw - o.adventitia_ratio * D, 3e-3);
      EXPECT_NEAR(w.radius[s][1][i], kRw - (o.adventitia_ratio + o.media_ratio) * D, 3e-3);
    }
  EXPECT_EQ(w.clamped_fraction, 0.0);
  EXPECT_NEAR(w.abscissa.back() - w.abscissa.front(), kL - 2 * o.end_trim, 1e-9);
}

TEST(PatientMesh, LayerVolumesMatchTheAnalyticOnes) {
  const auto& [m, w] = tet4_tube();
  const auto o = coarse("tet4");
  const double len = kL - 2 * o.end_trim, D = 2 * kRw;
  const double r2 = kRw - o.adventitia_ratio * D, r1 = r2 - o.media_ratio * D;
  const std::map<int, double> exact = {{tags::intima, std::numbers::pi * (r1 * r1 - kRl * kRl) * len},
                                       {tags::media, std::numbers::pi * (r2 * r2 - r1 * r1) * len},
                                       {tags::adventitia, std::numbers::pi * (kRw * kRw - r2 * r2) * len}};
  std::map<int, double> vol;
  const auto& layer = m.cell_data.at(tags::kLayer);
  for (std::size_t c = 0; c < m.num_cells(); ++c)
    if (m.cell_types[c] == CellType::tetra) {
      const double v = tet_volume(m, c);
      EXPECT_GT(v, 0) << "inverted tet " << c;
      vol[int(layer.at(c))] += v;
    }
  // Straight-sided tets under-fill curved interfaces by O(h^2/r): a few % at h = 0.4.
  for (auto [L, v] : exact) EXPECT_NEAR(vol[L] / v, 1.0, 0.03) << tags::layer_name(L);
}

TEST(PatientMesh, ConformingTaggedAndOutward) {
  const auto& m = tet4_tube().mesh;
  // Every tet face is shared by two tets (also across layer interfaces) or is
  // one tagged boundary face.
  std::map<std::array<std::int64_t, 3>, int> tet_faces, tagged;
  std::map<std::array<std::int64_t, 3>, std::set<int>> face_layers;
  const auto& layer = m.cell_data.at(tags::kLayer);
  const auto& group = m.cell_data.at(tags::kFaceGroup);
  std::map<int, int> per_group;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    auto n = m.cell(c);
    if (m.cell_types[c] == CellType::tetra) {
      static const int f[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
      for (auto& ff : f) {
        std::array<std::int64_t, 3> k = {n[std::size_t(ff[0])], n[std::size_t(ff[1])], n[std::size_t(ff[2])]};
        std::sort(k.begin(), k.end());
        ++tet_faces[k];
        face_layers[k].insert(int(layer.at(c)));
      }
    } else {
      ASSERT_EQ(m.cell_types[c], CellType::triangle);
      std::array<std::int64_t, 3> k = {n[0], n[1], n[2]};
      std::sort(k.begin(), k.end());
      ++tagged[k];
      const int g = int(group.at(c));
      ++per_group[g];
      // Outward: the normal leaves the wall.
      const Vector3d a = m.points[std::size_t(n[0])], b = m.points[std::size_t(n[1])], cc = m.points[std::size_t(n[2])];
      const Vector3d nn = (b - a).cross(cc - a).normalized(), x = (a + b + cc) / 3;
      const Vector3d radial = Vector3d(x.x(), x.y(), 0).normalized();
      if (g == tags::endothelium) EXPECT_LT(nn.dot(radial), -0.9);
      if (g == tags::outer_wall) EXPECT_GT(nn.dot(radial), 0.9);
      if (g == tags::proximal_cut) EXPECT_LT(nn.z(), -0.999);
      if (g == tags::distal_cut) EXPECT_GT(nn.z(), 0.999);
    }
  }
  for (int g : {tags::endothelium, tags::outer_wall, tags::proximal_cut, tags::distal_cut}) EXPECT_GT(per_group[g], 0) << g;
  std::size_t interface_faces = 0;
  for (auto& [k, cnt] : tet_faces) {
    ASSERT_LE(cnt, 2);
    if (cnt == 1) EXPECT_EQ(tagged.count(k), 1u);
    if (cnt == 2) EXPECT_EQ(tagged.count(k), 0u);
    if (face_layers[k].size() == 2) ++interface_faces;
  }
  EXPECT_EQ(tagged.size(), [&] { std::size_t b = 0; for (auto& [k, c] : tet_faces) b += c == 1; return b; }());
  EXPECT_GT(interface_faces, 100u);  // intima/media and media/adventitia share faces
  // No duplicate nodes.
  std::vector<Vector3d> p = m.points;
  std::sort(p.begin(), p.end(), [](const Vector3d& a, const Vector3d& b) { return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z()); });
  for (std::size_t i = 1; i < p.size(); ++i) EXPECT_GT((p[i] - p[i - 1]).norm(), 1e-9);
}

TEST(PatientMesh, QualityWithinBounds) {
  const auto q = meshing::mesh_quality(tet4_tube().mesh);
  EXPECT_GT(q.min_scaled_jacobian, 0.1);
  EXPECT_LT(q.max_aspect_ratio, 20);
  for (int L : {1, 2, 3}) EXPECT_GT(q.elements_per_layer[std::size_t(L)], 0u);
}

TEST(PatientMesh, StageWritesVtuAndMshWithTet10) {
  const auto dir = std::filesystem::temp_directory_path() / "stentsim_test_patient_mesh";
  std::filesystem::create_directories(dir);
  write_vtp((dir / "lumen.vtp").string(), tube_surface(kRl));
  write_vtp((dir / "wall.vtp").string(), tube_surface(kRw));
  write_vtp((dir / "centerline.vtp").string(), tube_centerline());
  auto o = coarse("tet10");
  o.size = 0.5;
  Summary s;
  meshing::run_patient_mesh(dir / "lumen.vtp", dir / "wall.vtp", dir / "centerline.vtp", o, dir / "artery.vtu",
                            dir / "artery.msh", s);
  const MeshData m = read_vtu((dir / "artery.vtu").string());
  std::size_t t10 = 0, t6 = 0;
  for (auto t : m.cell_types) t10 += t == CellType::quadratic_tetra, t6 += t == CellType::quadratic_triangle;
  EXPECT_GT(t10, 100u);
  EXPECT_GT(t6, 50u);
  EXPECT_EQ(t10 + t6, m.num_cells());
  EXPECT_TRUE(std::filesystem::exists(dir / "artery.msh"));
  const std::string head = [&] { std::ifstream f(dir / "artery.msh"); std::string a, b; std::getline(f, a); std::getline(f, b); return b; }();
  EXPECT_EQ(head.substr(0, 3), "4.1");
  EXPECT_GT(std::get<double>(s.qois().at("min_scaled_jacobian").value), 0.1);
  // The estimate made before gmsh runs (mesh.max_elements) is within 2x of the count it makes.
  const double estimate = std::get<double>(s.qois().at("artery_elements_estimate").value);
  const double made = std::get<double>(s.qois().at("artery_elements").value);
  std::printf("tets: %.0f made, %.0f estimated\n", made, estimate);
  EXPECT_GT(estimate, 0.5 * made);
  EXPECT_LT(estimate, 2.0 * made);
}

TEST(PatientMesh, BadInputIsAnInputError) {
  const auto o = coarse("tet4");
  // wall inside the lumen
  EXPECT_THROW(meshing::wall_sections(tube_surface(kRw), tube_surface(kRl), tube_centerline(), o), InputError);
  // centerline without normals
  EXPECT_THROW(meshing::wall_sections(tube_surface(kRl), tube_surface(kRw), tube_centerline(false), o), InputError);
  // centerline outside the lumen: rays miss
  MeshData off = tube_centerline();
  for (auto& p : off.points) p.x() += 5;
  EXPECT_THROW(meshing::wall_sections(tube_surface(kRl), tube_surface(kRw), off, o), InputError);
  auto bad = o;
  bad.element = "hex27";
  EXPECT_THROW(meshing::validate(bad), InputError);
}

TEST(PatientMesh, Tet10QualitySeesMisplacedMidsideNodes) {
  // One regular-ish tet10 (VTK order: corners, then edges 01 12 02 03 13 23)
  // with its midside nodes at the edge midpoints: the quadratic map is affine,
  // the Jacobian ratio 1 and the scaled Jacobian the straight tet's.
  MeshData m;
  m.points = {Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0.5, std::sqrt(3.0) / 2, 0),
              Vector3d(0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0))};
  const int edge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  for (auto& e : edge) m.points.push_back(0.5 * (m.points[std::size_t(e[0])] + m.points[std::size_t(e[1])]));
  m.add_cell(CellType::quadratic_tetra, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
  m.cell_data[tags::kLayer] = {1, {double(tags::media)}};
  const auto straight = meshing::mesh_quality(m);
  EXPECT_NEAR(straight.min_scaled_jacobian, 1.0, 1e-12);
  EXPECT_NEAR(straight.min_jacobian_ratio, 1.0, 1e-12);
  EXPECT_NEAR(straight.mean_edge_length, 1.0, 1e-12);
  // Midside node of edge 01 pushed most of the way towards the opposite edge
  // 23: the corner tet is unchanged, but the quadratic map folds (det J < 0
  // at corner 0 and 1), which the straight-tet measure alone would miss.
  m.points[4] += 0.8 * (m.points[9] - m.points[4]);
  const auto bent = meshing::mesh_quality(m);
  EXPECT_LT(bent.min_jacobian_ratio, 0.0);
  EXPECT_LT(bent.min_scaled_jacobian, 0.0);
  // A mild displacement lowers it without inverting.
  m.points[4] = 0.5 * (m.points[0] + m.points[1]) + Vector3d(0, 0.05, 0.02);
  const auto mild = meshing::mesh_quality(m);
  EXPECT_GT(mild.min_jacobian_ratio, 0.5);
  EXPECT_LT(mild.min_jacobian_ratio, 0.999);
}

TEST(PatientMesh, Tet10InterfacesShareFacesAndMidsideNodes) {
  // The tet10 mesh is conforming across the layer interfaces: every corner
  // face is shared by at most two tets, interface faces exist, and each
  // edge has one midside node whichever tet (and layer) it is seen from.
  const auto o = [] { auto x = coarse("tet10"); x.size = 0.5; return x; }();
  const auto w = meshing::wall_sections(tube_surface(kRl), tube_surface(kRw), tube_centerline(), o);
  const MeshData m = meshing::mesh_wall_sections(w, o, std::filesystem::temp_directory_path() / "stentsim_test_tube10.msh");
  const auto& layer = m.cell_data.at(tags::kLayer);
  std::map<std::array<std::int64_t, 3>, std::set<int>> face_layers;
  std::map<std::array<std::int64_t, 3>, int> face_count;
  std::map<std::pair<std::int64_t, std::int64_t>, std::int64_t> midside;
  std::map<std::pair<std::int64_t, std::int64_t>, std::set<int>> edge_layers;
  const int edge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  std::size_t tets = 0;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    if (m.cell_types[c] != CellType::quadratic_tetra) continue;
    ++tets;
    const auto n = m.cell(c);
    static const int f[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
    for (auto& ff : f) {
      std::array<std::int64_t, 3> k = {n[std::size_t(ff[0])], n[std::size_t(ff[1])], n[std::size_t(ff[2])]};
      std::sort(k.begin(), k.end());
      ++face_count[k];
      face_layers[k].insert(int(layer.at(c)));
    }
    for (int e = 0; e < 6; ++e) {
      auto key = std::minmax(n[std::size_t(edge[e][0])], n[std::size_t(edge[e][1])]);
      auto [it, fresh] = midside.emplace(key, n[std::size_t(4 + e)]);
      ASSERT_EQ(it->second, n[std::size_t(4 + e)]) << "edge seen with two midside nodes";
      edge_layers[key].insert(int(layer.at(c)));
      // Straight midside nodes (Mesh.SecondOrderLinear).
      EXPECT_LT((m.points[std::size_t(n[std::size_t(4 + e)])] -
                 0.5 * (m.points[std::size_t(key.first)] + m.points[std::size_t(key.second)])).norm(), 1e-9);
    }
  }
  std::size_t interface_faces = 0, interface_edges = 0;
  for (auto& [k, cnt] : face_count) {
    ASSERT_LE(cnt, 2);
    interface_faces += face_layers[k].size() == 2;
  }
  for (auto& [k, ls] : edge_layers) interface_edges += ls.size() >= 2;
  std::printf("tet10 tube: %zu tets, %zu interface faces, %zu edges shared by two layers\n", tets, interface_faces, interface_edges);
  EXPECT_GT(interface_faces, 50u);
  EXPECT_GT(interface_edges, 50u);
  const auto q = meshing::mesh_quality(m);
  EXPECT_NEAR(q.min_jacobian_ratio, 1.0, 1e-9);
  EXPECT_GT(q.min_scaled_jacobian, 0.1);
}
