// `fiber_frames: {file: fibers.vtu}`: the solver takes each element's fiber
// directions from the fibers stage's Fiber1/Fiber2 arrays (DESIGN.md §5,
// fibers/analytic_tube_fibers.hpp). A media/adventitia tube sector whose
// artery VTU also holds boundary faces (as the mesh stage writes it) and a
// fibers.vtu of its volume cells:
//  - with the analytic tube field the result equals the per-body cylindrical
//    frames with the presets' angles (to solver tolerance);
//  - a field with the adventitia at +-60 deg gives the result of materials
//    whose angles are +-60 deg (so the file's fibers are used, not rebuilt
//    from its frames and the material's +-40 deg), and `fibers: none` goes
//    back to the material angles;
//  - a field for another mesh (cell count or centroids) or without Fiber2 is an
//    InputError naming the file.
#include <gtest/gtest.h>
#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <numbers>

#include <Eigen/Geometry>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "common/mesh_tags.hpp"
#include "fibers/analytic_tube_fibers.hpp"
#include "solver/app/solve.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"

namespace stentsim::solver {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = std::numbers::pi / 180.0;

MeshData artery(int nt) {
  MeshData m = ring_sector_hex8(0.8, 1.4, std::numbers::pi / 2, 0.3, 4, nt, 2);
  m.point_data.clear();
  DataArray layer{1, {}};
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (auto n : m.cell(c)) x += m.points[static_cast<std::size_t>(n)];
    layer.values.push_back((x / 8.0).head(2).norm() < 1.1 ? tags::media : tags::adventitia);
  }
  // The boundary faces as 2D cells with Layer 0, after the volume cells (as artery.vtu holds them).
  const auto faces = fem::boundary_faces(m);
  for (const auto& f : faces) {
    m.add_cell(CellType::quad, std::vector<std::int64_t>(f.nodes.begin(), f.nodes.begin() + f.count));
    layer.values.push_back(tags::no_layer);
  }
  m.cell_data[tags::kLayer] = layer;
  return m;
}

struct Case {
  fs::path dir;
  Case() {
    dir = fs::temp_directory_path() / fmt::format("stentsim_fiber_file_{}", ::getpid());
    fs::remove_all(dir);
    fs::create_directories(dir);
    write_vtu((dir / "artery.vtu").string(), artery(8));
  }
  ~Case() { fs::remove_all(dir); }

  /// Writes a scene; `frames` is the fiber_frames value, `adventitia` the tag-3 material.
  fs::path scene(const std::string& name, const std::string& frames,
                 const std::string& adventitia = "{tag: 3, preset: adventitia}") const {
    const fs::path p = dir / (name + ".yaml");
    std::ofstream(p) << fmt::format(R"(description: fiber field file vs analytic frames
bodies:
  - name: wall
    mesh: {{file: artery.vtu}}
    material_array: Layer
    materials:
      - {{tag: 2, preset: media}}
      - {adv}
    fiber_frames: {frames}
load_curves:
  ramp: [[0, 0], [1, 1]]
conditions:
  - {{name: lumen, type: pressure, body: wall, surface: {{cylinder: {{origin: [0, 0, 0], axis: [0, 0, 1], radius: 0.8 mm}}}}, value: 0.012 MPa, curve: ramp}}
  - {{name: plane_strain, type: dirichlet, body: wall, nodes: {{all: true}}, components: z}}
  - {{name: sym_xz, type: dirichlet, body: wall, nodes: {{plane: {{point: [0, 0, 0], normal: [0, 1, 0]}}}}, components: y}}
  - {{name: sym_yz, type: dirichlet, body: wall, nodes: {{plane: {{point: [0, 0, 0], normal: [1, 0, 0]}}}}, components: x}}
solver:
  time: {{start: 0, end: 1, dt: 0.5, dt_max: 0.5}}
  newton: {{max_iterations: 20, residual_tolerance: 1.0e-11}}
  linear: {{type: direct}}
output:
  every: 1
)",
                                    fmt::arg("adv", adventitia), fmt::arg("frames", frames));
    return p;
  }

  /// Solves and returns the final displacement (all points).
  std::vector<double> solve(const fs::path& scene) const {
    const fs::path out = dir / ("out_" + scene.stem().string());
    SolveOptions opt;
    opt.output_dir = out;
    EXPECT_EQ(solve_scene(scene, opt), 0) << scene;
    int last = 0;
    while (fs::exists(out / fmt::format("results/wall_{:05d}.vtu", last + 1))) ++last;
    EXPECT_EQ(last, 2);
    return read_vtu((out / fmt::format("results/wall_{:05d}.vtu", last)).string()).point_data.at("Displacement").values;
  }
};

double rel_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0, n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d += (a[i] - b[i]) * (a[i] - b[i]), n += b[i] * b[i];
  return std::sqrt(d / n);
}

const std::string kCylindrical = "{cylindrical: {origin: [0, 0, 0], axis: [0, 0, 1]}}";

TEST(SolverFiberFile, FileFibersMatchAnalyticFramesAndAreUsedAsGiven) {
  Case c;
  const MeshData mesh = read_vtu((c.dir / "artery.vtu").string());
  write_vtu((c.dir / "fibers.vtu").string(), fibers::tube_fibers(mesh, {{tags::media, 0.0}, {tags::adventitia, 40 * kDeg}}));
  write_vtu((c.dir / "fibers60.vtu").string(), fibers::tube_fibers(mesh, {{tags::media, 0.0}, {tags::adventitia, 60 * kDeg}}));
  const std::string adv60 =
      "{tag: 3, preset: adventitia, fibers: [{k1: 5.1 kPa, k2: 15.4, angle_deg: 60}, {k1: 5.1 kPa, k2: 15.4, angle_deg: -60}]}";

  const auto analytic = c.solve(c.scene("analytic", kCylindrical));
  const auto file = c.solve(c.scene("file", "{file: fibers.vtu}"));
  const auto analytic60 = c.solve(c.scene("analytic60", kCylindrical, adv60));
  const auto file60 = c.solve(c.scene("file60", "{file: fibers60.vtu, fibers: Fiber1 Fiber2}"));
  const auto file60_angles = c.solve(c.scene("file60_angles", "{file: fibers60.vtu, fibers: none}"));
  ASSERT_EQ(file.size(), analytic.size());
  const double d40 = rel_diff(file, analytic), d60 = rel_diff(file60, analytic60), d_angles = rel_diff(file60_angles, analytic),
               d_fibers = rel_diff(analytic60, analytic);
  std::printf("file vs cylindrical (+-40): %.2e; file +-60 vs materials +-60: %.2e; file +-60 with fibers: none vs +-40: %.2e; "
              "+-60 vs +-40 materials: %.2e\n",
              d40, d60, d_angles, d_fibers);
  EXPECT_LT(d40, 1e-9);
  EXPECT_LT(d60, 1e-9);
  EXPECT_LT(d_angles, 1e-9);
  EXPECT_GT(d_fibers, 1e-4) << "the adventitia angle does not change the result: the comparison cannot fail";
}

TEST(SolverFiberFile, MismatchedFieldIsAnInputError) {
  Case c;
  const fibers::LayerAngles angles{{tags::media, 0.0}, {tags::adventitia, 40 * kDeg}};
  auto expect_error = [&](const std::string& name, const std::string& frames, const std::vector<std::string>& words) {
    try {
      SolveOptions opt;
      opt.output_dir = c.dir / ("out_" + name);
      solve_scene(c.scene(name, frames), opt);
      ADD_FAILURE() << name << ": no error";
    } catch (const InputError& e) {
      std::printf("%s: %s\n", name.c_str(), e.what());
      for (const auto& w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << name << ": " << e.what();
    }
  };
  // Another mesh: 6 elements around instead of 8.
  write_vtu((c.dir / "other.vtu").string(), fibers::tube_fibers(artery(6), angles));
  expect_error("count", "{file: other.vtu}", {"other.vtu", "has 48 cells", "64 of them volume cells"});
  // Same cell count, other geometry (the sector turned by 10 deg).
  MeshData turned = read_vtu((c.dir / "artery.vtu").string());
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(10 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (auto& p : turned.points) p = rot * p;
  write_vtu((c.dir / "turned.vtu").string(), fibers::tube_fibers(turned, angles));
  expect_error("centroids", "{file: turned.vtu}", {"turned.vtu", "made for another mesh"});
  // No Fiber2 array (e.g. a frames-only file).
  MeshData no_f2 = fibers::tube_fibers(read_vtu((c.dir / "artery.vtu").string()), angles);
  no_f2.cell_data.erase("Fiber2");
  write_vtu((c.dir / "no_f2.vtu").string(), no_f2);
  expect_error("array", "{file: no_f2.vtu}", {"no_f2.vtu", "'Fiber2'", "fibers: none"});
  // A material with more families than the file's arrays.
  expect_error("families", "{file: no_f2.vtu, fibers: Fiber1}", {"2 fiber families", "1 direction(s) per cell"});
  // Fiber arrays that are not unit vectors.
  MeshData scaled = fibers::tube_fibers(read_vtu((c.dir / "artery.vtu").string()), angles);
  for (double& v : scaled.cell_data.at("Fiber1").values) v *= 2.0;
  write_vtu((c.dir / "scaled.vtu").string(), scaled);
  expect_error("unit", "{file: scaled.vtu}", {"'Fiber1' of cell 0 has length 2", "unit vector"});
}

}  // namespace
}  // namespace stentsim::solver
