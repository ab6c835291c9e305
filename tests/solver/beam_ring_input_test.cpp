// Beam scenes with plasticity, rigid joints and the release condition
// (issue 9): what the scene reader and the condition resolution accept and
// refuse. Fast: no load steps are solved.
// - `material: stent` gives the App. C preset with elasto-plastic bending;
// - stent files are coupled by rigid joints: DOFs of the 210-element stent
//   3,150 nodal → 2,694 after coupling (`joints: none` keeps 3,150), the
//   588-element one 8,820 → 7,524; the ring 720 → 624;
// - `node: joints` selects the 16 crown masters; a point on a joint selects
//   its master; a condition on a slave node ({index}) is an InputError naming
//   the node and its master;
// - release: unknown source, a curve that is not 1 at the release time and a
//   release time outside the run are InputErrors naming the condition;
// - `plastic:` on a generated cantilever: end rotation = closed form (1e-6).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "device_gen/stent_design.hpp"
#include "device_gen/stent_mesh.hpp"
#include "device_gen/stent_model.hpp"
#include "solver/app/solve.hpp"
#include "solver/io/scene.hpp"

namespace stentsim::solver {
namespace {

const std::filesystem::path kExamples = std::filesystem::path(STENTSIM_TEST_SOURCE_DIR) / "examples";

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("stentsim_ring_input_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("example has no '" + from + "'");
  return text.replace(at, from.size(), to);
}

std::string example() {
  return replaced(files::read_text(kExamples / "stent_ring_expansion.yaml"), "file: data/stent_ring_3el.vtu",
                  "file: " + (kExamples / "data/stent_ring_3el.vtu").string());
}

// The error of reading (and, with `solve`, of resolving the conditions of) a scene text.
std::string error_of(const std::string& text, bool solve = false) {
  const auto dir = fresh_dir("err");
  files::write_atomic(dir / "scene.yaml", text);
  try {
    if (solve) {
      SolveOptions o;
      o.output_dir = dir / "out";
      solve_scene(dir / "scene.yaml", o);
    } else {
      read_scene(dir / "scene.yaml");
    }
  } catch (const InputError& e) {
    std::filesystem::remove_all(dir);
    return e.what();
  }
  std::filesystem::remove_all(dir);
  return "";
}

}  // namespace

TEST(BeamRingInput, StentPresetJointsAndCrownSelection) {
  const auto dir = fresh_dir("ok");
  files::write_atomic(dir / "scene.yaml", example());
  const SceneDesc s = read_scene(dir / "scene.yaml");
  ASSERT_EQ(s.bodies.size(), 1u);
  const beams::BeamBodyDesc& b = *s.bodies[0].beam;
  ASSERT_TRUE(b.body.section.plastic.has_value());
  EXPECT_EQ(b.body.section.plastic->E, 380000.0);
  EXPECT_EQ(b.body.section.plastic->G, 190000.0);
  EXPECT_EQ(b.body.section.plastic->E_ep, 64000.0);
  EXPECT_EQ(b.body.section.plastic->M_y0, 0.08);
  EXPECT_DOUBLE_EQ(b.body.section.plastic->radius, 0.06);
  EXPECT_EQ(b.body.elements.size(), 48u);
  GlobalDof n = 0;
  b.number_dofs(0, &n);
  EXPECT_EQ(beams::beam_nodal_dof_count(b.body), 720);
  EXPECT_EQ(n, 624);  // 16 slave nodes lose their 6 position and rotation DOFs
  beams::BeamNodeSelector joints;
  joints.kind = beams::BeamNodeSelector::Kind::joints;
  const auto crowns = beams::select_beam_nodes(b, joints);
  EXPECT_EQ(crowns.size(), 16u);
  for (int c : crowns) EXPECT_FALSE(b.joint_map.is_slave(c));
  beams::BeamNodeSelector at;
  at.kind = beams::BeamNodeSelector::Kind::point;
  at.point = Vec3(0.575, 0, -0.75);
  EXPECT_EQ(beams::select_beam_nodes(b, at), std::vector<int>{0});  // nodes 0 and 111 meet there; 0 is the master
  // the release is a stop of the stepping
  EXPECT_NE(std::find(s.stepping.stops.begin(), s.stepping.stops.end(), 20.0), s.stepping.stops.end());
  std::filesystem::remove_all(dir);
}

TEST(BeamRingInput, StentDofCountsWithAndWithoutJoints) {
  // 4 rings: 210 elements, 3,150 → 2,694 DOFs; 11 rings: 588 elements, 8,820 → 7,524
  for (const int rings : {4, 11}) {
  device_gen::StentDesign d;
  d.rings = rings;
  const auto model = device_gen::build_stent(d, device_gen::DeviceAxis::straight(d.length()));
  const auto dir = fresh_dir("stent");
  write_vtu((dir / "stent.vtu").string(), device_gen::stent_to_mesh(model, d));
  const std::size_t elements = rings == 4 ? 210 : 588;
  const GlobalDof nodal = rings == 4 ? 3150 : 8820, coupled = rings == 4 ? 2694 : 7524;
  for (const std::string joints : {"rigid", "none"}) {
    const std::string text = fmt::format(R"(bodies:
  - name: stent
    beam: {{file: stent.vtu, material: stent, joints: {}}}
conditions:
  - {{name: hold, type: clamp, body: stent, node: fixations}}
solver: {{time: {{end: 1}}}}
output: {{every: 1}}
)", joints);
    files::write_atomic(dir / "scene.yaml", text);
    const SceneDesc s = read_scene(dir / "scene.yaml");
    const beams::BeamBodyDesc& b = *s.bodies[0].beam;
    GlobalDof n = 0;
    b.number_dofs(0, &n);
    EXPECT_EQ(b.body.elements.size(), elements);
    EXPECT_EQ(beams::beam_nodal_dof_count(b.body), nodal);
    EXPECT_EQ(n, joints == "rigid" ? coupled : nodal) << joints << ", " << rings << " rings";
  }
  std::filesystem::remove_all(dir);
  }
}

TEST(BeamRingInput, ConditionOnASlaveNodeNamesIt) {
  const std::string text = replaced(example(), "  - name: release_crowns",
                                    "  - {name: bad_clamp, type: clamp, body: ring, node: {index: [111]}}\n"
                                    "  - name: release_crowns");
  const std::string e = error_of(text, true);
  EXPECT_NE(e.find("bad_clamp"), std::string::npos) << e;
  EXPECT_NE(e.find("node 111 is the slave of a rigid joint"), std::string::npos) << e;
  EXPECT_NE(e.find("master node 0"), std::string::npos) << e;
}

TEST(BeamRingInput, ReleaseIsValidated) {
  std::string e = error_of(replaced(example(), "from: crowns_radial", "from: nothing"));
  EXPECT_NE(e.find("no radial_displacement condition named 'nothing'"), std::string::npos) << e;
  e = error_of(replaced(example(), "unload: [[20, 1], [30, 0]]", "unload: [[20, 0.5], [30, 0]]"));
  EXPECT_NE(e.find("must be 1 at the release time"), std::string::npos) << e;
  e = error_of(replaced(example(), "    at: 20\n", "    at: 0\n"));
  EXPECT_NE(e.find("release_crowns"), std::string::npos) << e;
  EXPECT_NE(e.find("must lie inside solver.time"), std::string::npos) << e;
  e = error_of(replaced(example(), "material: stent", "material: stent\n      E: 1000 MPa"));
  EXPECT_NE(e.find("the stent preset sets E, G"), std::string::npos) << e;
}

}  // namespace stentsim::solver

namespace stentsim::solver {

// `plastic:` on a generated body: a cantilever (L = 0.2, R = 0.06, stent
// law) under an end moment of 0.2 N mm past yield; uniform moment, so the end
// rotation is κL with κ = M_y0/EI + (M − M_y0)/(E_ep I) (App. C hardening).
TEST(BeamRingInput, GeneratedBodyWithPlasticKeyMatchesClosedForm) {
  const auto dir = std::filesystem::temp_directory_path() / ("stentsim_ring_input_plastic_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  files::write_atomic(dir / "scene.yaml", R"(bodies:
  - name: bar
    beam:
      generate: {type: line, start: [0, 0, 0], end: [0.2, 0, 0], elements: 3, d2: [0, 1, 0]}
      section: {radius: 0.06 mm}
      E: 380000 MPa
      G: 190000 MPa
      plastic: {E_ep: 64000 MPa, M_y0: 0.08}
load_curves:
  ramp: [[0, 0], [1, 1]]
conditions:
  - {name: root, type: clamp, body: bar, node: first}
  - {name: moment, type: point_moment, body: bar, node: last, value: [0, 0, 0.2], curve: ramp}
solver:
  time: {start: 0, end: 1, dt: 0.1, dt_max: 0.1}
  newton: {max_iterations: 30, residual_tolerance: 1.0e-10, residual_absolute: 1.0e-10, increment_tolerance: 1.0e-12, line_search_steps: 0}
  linear: {type: eigen_lu}
output:
  every: 10
qoi:
  - {name: tip_rotation_angle, type: tip_rotation_angle, body: bar, node: last}
)");
  SolveOptions o;
  o.output_dir = dir / "out";
  ASSERT_EQ(solve_scene(dir / "scene.yaml", o), 0);
  const Summary s = Summary::read(dir / "out/summary.yaml");
  const double I = std::numbers::pi * std::pow(0.06, 4) / 4.0;
  const double kappa = 0.08 / (380000.0 * I) + (0.2 - 0.08) / (64000.0 * I);
  const double angle = std::get<double>(s.qois().at("tip_rotation_angle").value);
  std::printf("plastic cantilever from a scene: tip rotation %.9f, closed form %.9f\n", angle, kappa * 0.2);
  EXPECT_NEAR(angle, kappa * 0.2, 1e-6);
  const MeshData m = read_vtu((dir / "out/results/bar_00001.vtu").string());
  EXPECT_TRUE(m.point_data.count("PlasticCurvature") && m.point_data.count("Yielding") &&
              m.point_data.count("OuterFibrePlasticStrain") && m.point_data.count("AccumulatedPlasticCurvature"));
  std::filesystem::remove_all(dir);
}

}  // namespace stentsim::solver
