// Patient wall mesh, review of issue 5: elements through each layer
// (min_elements_per_layer honoured or an InputError, never clamped), a layer
// left out, the quality-bound errors (where, and no files left), and the tags
// read back from artery.vtu and artery.msh (gmsh 4.1 physical groups).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"
#include "meshing/patient_mesh.hpp"
#include "tube_fixtures.hpp"

using namespace stentsim;
using Eigen::Vector3d;

namespace {

std::array<Vector3d, 4> corners(const MeshData& m, std::size_t c) {
  auto n = m.cell(c);
  return {m.points[std::size_t(n[0])], m.points[std::size_t(n[1])], m.points[std::size_t(n[2])],
          m.points[std::size_t(n[3])]};
}

double tet_volume(const std::array<Vector3d, 4>& x) { return (x[1] - x[0]).dot((x[2] - x[0]).cross(x[3] - x[0])) / 6; }

/// Length of the segment a + u (b - a), u in [0, 1], inside the tet (clipping
/// by its four face half-spaces).
double inside_length(const std::array<Vector3d, 4>& x, const Vector3d& a, const Vector3d& b) {
  double u0 = 0, u1 = 1;
  static const int f[4][4] = {{1, 2, 3, 0}, {0, 2, 3, 1}, {0, 1, 3, 2}, {0, 1, 2, 3}};  // face, opposite corner
  for (auto& ff : f) {
    Vector3d n = (x[ff[1]] - x[ff[0]]).cross(x[ff[2]] - x[ff[0]]);
    if (n.dot(x[ff[3]] - x[ff[0]]) > 0) n = -n;  // outward
    const double da = n.dot(a - x[ff[0]]), db = n.dot(b - x[ff[0]]);  // inside: <= 0
    if (da > 0 && db > 0) return 0;
    if (da > 0) u0 = std::max(u0, da / (da - db));
    else if (db > 0) u1 = std::min(u1, da / (da - db));
  }
  return std::max(0.0, u1 - u0) * (b - a).norm();
}

meshing::PatientMeshOptions coarse_tet4() {
  meshing::PatientMeshOptions o;
  o.element = "tet4";
  o.size = 0.4;
  o.station_spacing = 0.5;
  return o;
}

constexpr double kL = 4.0, kRl = 1.0, kRw = 2.0;

std::filesystem::path stage_inputs(const std::string& name, double rl = kRl, double rw = kRw, double len = kL) {
  const auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  write_vtp((dir / "lumen.vtp").string(), test::straight_tube(rl, len));
  write_vtp((dir / "wall.vtp").string(), test::straight_tube(rw, len));
  write_vtp((dir / "centerline.vtp").string(), test::straight_centerline(len));
  return dir;
}

// A short tube with a 0.6 mm wall, no intima, media and adventitia 0.3 mm each.
constexpr double kThinL = 1.4, kThinRl = 0.5, kThinRw = 1.1;

struct LayerCount {
  double mean_edge = 0;     // mean corner edge length of the layer's tets, mm
  int min_crossed = 1 << 30;  // fewest tets of the layer along a radial ray
  double thickness = 0;
};

std::map<int, LayerCount> count_through_layers(int n) {
  auto o = coarse_tet4();
  o.size = 0.5;
  // The floor below t / n (the faceted layer is a hair under 0.3 mm); at
  // the default 0.5 (0.25 mm) the old code clamped both n to 0.25 mm, now
  // that is the InputError of the next test.
  o.min_size_ratio = n == 2 ? 0.28 : 0.18;
  o.intima = false;
  o.media_ratio = o.adventitia_ratio = 0.1;
  o.station_spacing = 0.25;
  o.min_elements_per_layer = n;
  const auto w = meshing::wall_sections(test::straight_tube(kThinRl, kThinL), test::straight_tube(kThinRw, kThinL),
                                        test::straight_centerline(kThinL), o);
  const auto m = meshing::mesh_wall_sections(w, o, std::filesystem::temp_directory_path() / "stentsim_test_layers.msh");
  const auto& layer = m.cell_data.at(tags::kLayer);
  std::map<int, LayerCount> out;
  std::map<int, std::pair<double, int>> edges;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    if (m.cell_types[c] != CellType::tetra) continue;
    const auto x = corners(m, c);
    auto& [sum, cnt] = edges[int(layer.at(c))];
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) sum += (x[std::size_t(i)] - x[std::size_t(j)]).norm(), ++cnt;
  }
  for (auto& [L, e] : edges) out[L].mean_edge = e.first / e.second;
  out[tags::media].thickness = w.radius[0][1][0] - w.radius[0][0][0];
  out[tags::adventitia].thickness = w.radius[0][2][0] - w.radius[0][1][0];
  // Radial rays at odd angles and heights (off the sections' nodes and faces).
  for (int r = 0; r < 12; ++r) {
    const double th = 0.37 + 2 * std::numbers::pi * r / 12, z = 0.45 + 0.05 * r;
    const Vector3d d(std::cos(th), std::sin(th), 0), a = Vector3d(0, 0, z) + 0.4 * d, b = Vector3d(0, 0, z) + 1.2 * d;
    std::map<int, int> crossed;
    for (std::size_t c = 0; c < m.num_cells(); ++c)
      if (m.cell_types[c] == CellType::tetra && inside_length(corners(m, c), a, b) > 1e-9) ++crossed[int(layer.at(c))];
    for (int L : {tags::media, tags::adventitia}) out[L].min_crossed = std::min(out[L].min_crossed, crossed[L]);
  }
  return out;
}

}  // namespace

// Item 1: the per-layer count is honoured: mean edge below 1.35 t / n, at
// least n tets of the layer along each radial ray, and the size scales as
// 1 / n. (The silent clamp itself is caught by the InputError test below.)
TEST(PatientMeshLayers, ElementsThroughEachLayerHonourMinElementsPerLayer) {
  std::map<int, std::map<int, LayerCount>> by_n;
  for (int n : {2, 3}) {
    const auto& c = by_n[n] = count_through_layers(n);
    for (int L : {tags::media, tags::adventitia}) {
      const auto& x = c.at(L);
      ASSERT_NEAR(x.thickness, 0.3, 0.01);
      // gmsh's Delaunay tets have a mean corner edge ~1.2-1.25 x the target
      // here (measured 0.178 / 0.150 at n = 2, 0.125 / 0.100 at n = 3).
      EXPECT_LT(x.mean_edge, 1.35 * x.thickness / n) << tags::layer_name(L) << " n = " << n;
      EXPECT_GE(x.min_crossed, n) << tags::layer_name(L) << " n = " << n;
      std::printf("n = %d %s: thickness %.3f mm, mean edge %.4f mm (t/n = %.4f), fewest tets along a ray %d\n", n,
                  tags::layer_name(L), x.thickness, x.mean_edge, x.thickness / n, x.min_crossed);
    }
  }
  // The size follows 1 / n: 2/3 from n = 2 to n = 3 (a clamp would keep it).
  for (int L : {tags::media, tags::adventitia})
    EXPECT_NEAR(by_n[3].at(L).mean_edge / by_n[2].at(L).mean_edge, 2.0 / 3.0, 0.08) << tags::layer_name(L);
}

// Item 1: a per-layer size below the floor is an InputError naming both settings.
TEST(PatientMeshLayers, PerLayerCountBelowTheSizeFloorIsAnInputError) {
  auto o = coarse_tet4();
  o.size = 0.5;
  o.min_size_ratio = 0.25;  // floor 0.125 mm; the 0.3 mm layers with n = 3 need 0.1 mm
  o.station_spacing = 0.25;
  o.intima = false;
  o.media_ratio = o.adventitia_ratio = 0.1;
  o.min_elements_per_layer = 3;
  const auto w = meshing::wall_sections(test::straight_tube(kThinRl, kThinL), test::straight_tube(kThinRw, kThinL),
                                        test::straight_centerline(kThinL), o);
  try {
    meshing::mesh_wall_sections(w, o, std::filesystem::temp_directory_path() / "stentsim_test_layers_err.msh");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string s = e.what();
    EXPECT_NE(s.find("mesh.min_elements_per_layer = 3"), std::string::npos) << s;
    EXPECT_NE(s.find("mesh.min_size_ratio"), std::string::npos) << s;
    EXPECT_TRUE(s.find("media") != std::string::npos || s.find("adventitia") != std::string::npos) << s;
  }
  EXPECT_THROW(meshing::check_layer_sizing(w, o), InputError);
  o.min_elements_per_layer = 2;  // 0.15 mm >= 0.125: accepted
  EXPECT_NO_THROW(meshing::check_layer_sizing(w, o));
  o.min_size_ratio = 0.32;  // floor 0.16 mm > 0.15: rejected
  EXPECT_THROW(meshing::check_layer_sizing(w, o), InputError);
  o.min_size_ratio = 0.5;  // the default: n = 2 is rejected, n = 1 is a floor only
  EXPECT_THROW(meshing::check_layer_sizing(w, o), InputError);
  o.min_elements_per_layer = 1;
  EXPECT_NO_THROW(meshing::check_layer_sizing(w, o));
}

// Item 2: the intima left out (paper Case 1): media and adventitia only,
// filling the wall in the ratio media_ratio : adventitia_ratio.
TEST(PatientMeshLayers, IntimaLeftOutGivesMediaAndAdventitiaOnly) {
  auto o = coarse_tet4();
  o.intima = false;
  const auto w = meshing::wall_sections(test::straight_tube(kRl, kL), test::straight_tube(kRw, kL),
                                        test::straight_centerline(kL), o);
  ASSERT_EQ(w.layers, (std::vector<int>{tags::media, tags::adventitia}));
  const auto m = meshing::mesh_wall_sections(w, o, std::filesystem::temp_directory_path() / "stentsim_test_nointima.msh");
  const double rma = kRw - (kRw - kRl) * o.adventitia_ratio / (o.media_ratio + o.adventitia_ratio);
  const double len = kL - 2 * o.end_trim;
  const std::map<int, double> exact = {{tags::media, std::numbers::pi * (rma * rma - kRl * kRl) * len},
                                       {tags::adventitia, std::numbers::pi * (kRw * kRw - rma * rma) * len}};
  const auto& layer = m.cell_data.at(tags::kLayer);
  const auto& face = m.cell_data.at(tags::kFaceGroup);
  std::map<int, double> vol;
  std::map<int, int> faces;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    if (m.cell_types[c] == CellType::tetra) {
      const int L = int(layer.at(c));
      EXPECT_TRUE(L == tags::media || L == tags::adventitia) << "tet " << c << " Layer " << L;
      EXPECT_EQ(face.at(c), tags::no_face);
      vol[L] += tet_volume(corners(m, c));
    } else {
      ASSERT_EQ(m.cell_types[c], CellType::triangle);
      EXPECT_EQ(layer.at(c), tags::no_layer);
      const int g = int(face.at(c));
      ++faces[g];
      auto n = m.cell(c);
      Vector3d ctr = Vector3d::Zero();
      for (int j = 0; j < 3; ++j) ctr += m.points[std::size_t(n[std::size_t(j)])] / 3;
      const double r = ctr.head<2>().norm();
      if (g == tags::endothelium) {
        EXPECT_NEAR(r, kRl, 0.03);
      } else if (g == tags::outer_wall) {
        EXPECT_NEAR(r, kRw, 0.03);
      } else if (g == tags::proximal_cut) {
        EXPECT_NEAR(ctr.z(), o.end_trim, 1e-6);
      } else if (g == tags::distal_cut) {
        EXPECT_NEAR(ctr.z(), kL - o.end_trim, 1e-6);
      } else {
        ADD_FAILURE() << "FaceGroup " << g;
      }
    }
  }
  EXPECT_EQ(vol.size(), 2u);
  for (int g : {tags::endothelium, tags::outer_wall, tags::proximal_cut, tags::distal_cut}) EXPECT_GT(faces[g], 0) << g;
  // Straight-sided tets under-fill the curved faces by O(h^2 / r): within 3 %.
  for (auto [L, v] : exact) EXPECT_NEAR(vol[L] / v, 1.0, 0.03) << tags::layer_name(L);
  // The thickness ratio: media / adventitia volumes of the exact annuli differ
  // from 0.0786 / 0.136 by the radius weighting only; compare the interface radius.
  EXPECT_NEAR(w.radius[0][1][0], rma, 2e-3);
}

namespace {
/// Parses "(x, y, z)" after " at " in an error message.
Vector3d position_in(const std::string& s) {
  std::smatch mm;
  const std::regex re(R"(at \((-?[0-9.]+), (-?[0-9.]+), (-?[0-9.]+)\))");
  if (!std::regex_search(s, mm, re)) return Vector3d::Constant(1e9);
  return {std::stod(mm[1]), std::stod(mm[2]), std::stod(mm[3])};
}

void expect_no_outputs(const std::filesystem::path& dir) {
  EXPECT_FALSE(std::filesystem::exists(dir / "artery.vtu"));
  EXPECT_FALSE(std::filesystem::exists(dir / "artery.msh"));
  for (auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().extension() == ".msh" || e.path().extension() == ".vtu", false) << e.path();
}
}  // namespace

// Item 3: a quality bound the mesh misses is a ComputeError naming the
// setting, the layer and a position inside the wall; nothing is written.
void expect_quality_error_saying_where(const char* name, const meshing::PatientMeshOptions& o, const std::string& key) {
  const auto dir = stage_inputs(name);
  Summary s;
  try {
    meshing::run_patient_mesh(dir / "lumen.vtp", dir / "wall.vtp", dir / "centerline.vtp", o, dir / "artery.vtu",
                              dir / "artery.msh", s);
    FAIL() << "no error";
  } catch (const ComputeError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(key), std::string::npos) << m;
    EXPECT_TRUE(m.find("in the intima") != std::string::npos || m.find("in the media") != std::string::npos ||
                m.find("in the adventitia") != std::string::npos) << m;
    const Vector3d p = position_in(m);
    EXPECT_GT(p.head<2>().norm(), kRl - 0.05) << m;
    EXPECT_LT(p.head<2>().norm(), kRw + 0.05) << m;
    EXPECT_GT(p.z(), 0.0) << m;
    EXPECT_LT(p.z(), kL) << m;
  }
  expect_no_outputs(dir);
}

// A size far too small would mesh for hours, one far too large crashes gmsh: both are
// refused before gmsh runs, naming the setting and (too small) the estimated count.
TEST(PatientMeshLayers, ElementBudgetRefusesAbsurdSizesBeforeMeshing) {
  const auto dir = stage_inputs("stentsim_test_element_budget");
  auto o = coarse_tet4();
  Summary s;
  auto error_at = [&](double size) -> std::string {
    o.size = size;
    try {
      meshing::run_patient_mesh(dir / "lumen.vtp", dir / "wall.vtp", dir / "centerline.vtp", o, dir / "artery.vtu",
                                dir / "artery.msh", s);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string tiny = error_at(1e-4);
  EXPECT_NE(tiny.find("tets are expected at mesh.size = 0.0001 mm"), std::string::npos) << tiny;
  EXPECT_NE(tiny.find("mesh.max_elements"), std::string::npos) << tiny;
  const std::string huge = error_at(50.0);
  EXPECT_NE(huge.find("twice the thickest wall"), std::string::npos) << huge;
  // The bound is the setting: a budget below the default mesh's estimate refuses it too.
  o.max_elements = 10;
  EXPECT_NE(error_at(0.5).find("more than mesh.max_elements = 10"), std::string::npos);
  expect_no_outputs(dir);
}

TEST(PatientMeshLayers, ScaledJacobianBelowTheBoundIsAnErrorSayingWhere) {
  auto o = coarse_tet4();
  o.size = 0.5;
  o.min_scaled_jacobian = 0.3;  // Delaunay tet4 meshes have slivers well below 0.3
  expect_quality_error_saying_where("stentsim_test_quality_sj", o, "mesh.min_scaled_jacobian");
}

TEST(PatientMeshLayers, AspectRatioAboveTheBoundIsAnErrorSayingWhere) {
  auto o = coarse_tet4();
  o.size = 0.5;
  o.min_scaled_jacobian = 0;
  o.max_aspect_ratio = 1.2;  // only near-regular tets pass; gmsh's worst is several
  expect_quality_error_saying_where("stentsim_test_quality_ar", o, "mesh.max_aspect_ratio");
}

// Item 3: mesh_quality's worst aspect ratio position and layer (two tets: a
// regular one in the media, a flattened one in the adventitia).
TEST(PatientMeshLayers, QualityLocatesTheWorstAspectRatio) {
  MeshData m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}, {0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0)},
              {10, 0, 0}, {11, 0, 0}, {10.5, std::sqrt(3.0) / 2, 0}, {10.5, std::sqrt(3.0) / 6, 0.05}};
  m.add_cell(CellType::tetra, {0, 1, 2, 3});
  m.add_cell(CellType::tetra, {4, 5, 6, 7});
  m.cell_data[tags::kLayer] = DataArray{1, {double(tags::media), double(tags::adventitia)}};
  m.cell_data[tags::kFaceGroup] = DataArray{1, {0, 0}};
  const auto q = meshing::mesh_quality(m);
  EXPECT_GT(q.max_aspect_ratio, 5);
  EXPECT_EQ(q.worst_ar_layer, tags::adventitia);
  EXPECT_EQ(q.worst_ar_cell, 1u);
  EXPECT_NEAR((q.worst_ar_position - Vector3d(10.5, std::sqrt(3.0) / 6, 0.0125)).norm(), 0, 1e-12);
}

namespace {
/// Counts of elements per physical group of a gmsh 4.1 ASCII file and the
/// groups' names: {dim, tag} -> (name, elements).
std::map<std::pair<int, int>, std::pair<std::string, int>> msh_physical_groups(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::string line;
  std::map<std::pair<int, int>, std::pair<std::string, int>> groups;
  std::map<std::pair<int, int>, std::vector<int>> entity_groups;  // {dim, entity} -> physical tags
  while (std::getline(f, line)) {
    if (line == "$MeshFormat") {
      std::getline(f, line);
      EXPECT_EQ(line.substr(0, 3), "4.1");
      EXPECT_EQ(line.substr(4, 1), "0") << "not ASCII";
    } else if (line == "$PhysicalNames") {
      int n;
      f >> n;
      for (int i = 0; i < n; ++i) {
        int d, t;
        std::string name;
        f >> d >> t;
        std::getline(f, name);
        name = name.substr(name.find('"') + 1);
        name = name.substr(0, name.find('"'));
        groups[{d, t}] = {name, 0};
      }
    } else if (line == "$Entities") {
      std::size_t np, nc, ns, nv;
      f >> np >> nc >> ns >> nv;
      std::getline(f, line);
      for (std::size_t i = 0; i < np + nc + ns + nv; ++i) {
        std::getline(f, line);
        const int dim = i < np ? 0 : i < np + nc ? 1 : i < np + nc + ns ? 2 : 3;
        std::istringstream is(line);
        int tag, nphys;
        double x;
        is >> tag;
        for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) is >> x;
        is >> nphys;
        for (int k = 0; k < nphys; ++k) {
          int ph;
          is >> ph;
          entity_groups[{dim, tag}].push_back(std::abs(ph));
        }
      }
    } else if (line == "$Elements") {
      std::size_t blocks, total, lo, hi;
      f >> blocks >> total >> lo >> hi;
      for (std::size_t b = 0; b < blocks; ++b) {
        int dim, ent, type;
        std::size_t n;
        f >> dim >> ent >> type >> n;
        std::getline(f, line);
        for (std::size_t e = 0; e < n; ++e) std::getline(f, line);
        for (int ph : entity_groups[{dim, ent}]) groups[{dim, ph}].second += int(n);
      }
    }
  }
  return groups;
}
}  // namespace

// Item 4: artery.vtu and artery.msh carry the same tags, with the same counts.
TEST(PatientMeshLayers, WrittenFilesCarryLayerAndFaceGroupTags) {
  const auto dir = stage_inputs("stentsim_test_written_tags");
  auto o = coarse_tet4();
  o.size = 0.5;
  Summary s;
  meshing::run_patient_mesh(dir / "lumen.vtp", dir / "wall.vtp", dir / "centerline.vtp", o, dir / "artery.vtu",
                            dir / "artery.msh", s);
  const MeshData v = read_vtu((dir / "artery.vtu").string());
  ASSERT_TRUE(v.cell_data.count(tags::kLayer));
  ASSERT_TRUE(v.cell_data.count(tags::kFaceGroup));
  const auto& layer = v.cell_data.at(tags::kLayer);
  const auto& face = v.cell_data.at(tags::kFaceGroup);
  ASSERT_EQ(layer.tuples(), v.num_cells());
  ASSERT_EQ(face.tuples(), v.num_cells());
  std::map<int, int> vtu_layers, vtu_faces;
  for (std::size_t c = 0; c < v.num_cells(); ++c) {
    if (v.cell_types[c] == CellType::tetra) {
      EXPECT_EQ(face.at(c), tags::no_face);
      ++vtu_layers[int(layer.at(c))];
    } else {
      ASSERT_EQ(v.cell_types[c], CellType::triangle);
      EXPECT_EQ(layer.at(c), tags::no_layer);
      ++vtu_faces[int(face.at(c))];
    }
  }
  EXPECT_EQ(vtu_layers.size(), 3u);
  for (int L : {tags::intima, tags::media, tags::adventitia}) EXPECT_GT(vtu_layers[L], 0) << L;
  EXPECT_EQ(vtu_faces.size(), 4u);
  // The summary's per-layer counts are the file's.
  for (int L : {tags::intima, tags::media, tags::adventitia})
    EXPECT_EQ(std::get<double>(s.qois().at(std::string(tags::layer_name(L)) + "_elements").value), double(vtu_layers[L]));

  const auto groups = msh_physical_groups(dir / "artery.msh");
  EXPECT_EQ(groups.size(), 7u);
  for (int L : {tags::intima, tags::media, tags::adventitia}) {
    ASSERT_TRUE(groups.count({3, L})) << L;
    EXPECT_EQ(groups.at({3, L}).first, tags::layer_name(L));
    EXPECT_EQ(groups.at({3, L}).second, vtu_layers[L]) << tags::layer_name(L);
  }
  for (int g : {tags::endothelium, tags::outer_wall, tags::proximal_cut, tags::distal_cut}) {
    ASSERT_TRUE(groups.count({2, g})) << g;
    EXPECT_EQ(groups.at({2, g}).first, tags::face_group_name(g));
    EXPECT_EQ(groups.at({2, g}).second, vtu_faces[g]) << tags::face_group_name(g);
  }
}
