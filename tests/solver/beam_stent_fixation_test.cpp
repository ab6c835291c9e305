// The stent file's fixations through `direction: file` (issue 8, paper 2.2):
// the four radial fixation nodes move only along their radial direction, the
// axial one is "fixed along" the axis (d·u = 0) and free to move in the plane
// normal to it, so the stent can expand. Loaded by a point force on the axial
// node with radial, circumferential and axial parts (4 steps, elastic, the
// 210-element 4-ring stent): its in-plane displacement must be non-zero and
// its axial displacement zero; the radial nodes stay on their radial lines.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "device_gen/device_axis.hpp"
#include "device_gen/stent_design.hpp"
#include "device_gen/stent_mesh.hpp"
#include "device_gen/stent_model.hpp"
#include "solver/app/solve.hpp"
#include "solver/beams/stent_body.hpp"

namespace stentsim::solver {
namespace {

TEST(BeamStentFixation, AxialNodeExpandsRadiallyAndRadialNodesStayOnTheirLines) {
  const auto dir = std::filesystem::temp_directory_path() / ("stentsim_stent_fixation_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  device_gen::StentDesign design;  // 4 rings, 210 elements
  const auto model = device_gen::build_stent(design, device_gen::DeviceAxis::straight(design.length()));
  const MeshData mesh = device_gen::stent_to_mesh(model, design);
  write_vtu((dir / "stent.vtu").string(), mesh);
  const beams::StentBeams s = beams::stent_beams_from_mesh(mesh, 380000.0, 190000.0, "stent.vtu");
  ASSERT_EQ(s.fixations.size(), 5u);
  ASSERT_TRUE(s.fixations[4].axial);
  const Eigen::Vector3d axial_d = s.fixations[4].direction;
  const Eigen::Vector3d X_axial = s.body.nodes[static_cast<std::size_t>(s.fixations[4].node)].position;
  // The force: along the axial node's reference radial direction, around and along the axis.
  Eigen::Vector3d er = X_axial - X_axial.dot(axial_d) * axial_d;  // the axis passes through the origin's xy
  er -= er.dot(axial_d) * axial_d;
  er.normalize();
  const Eigen::Vector3d F = 0.05 * (er + axial_d.cross(er) + axial_d);
  auto point = [](const Eigen::Vector3d& x) { return fmt::format("{{point: [{:.17g}, {:.17g}, {:.17g}]}}", x[0], x[1], x[2]); };
  std::string qoi;
  for (std::size_t k = 0; k < 5; ++k)
    qoi += fmt::format("  - {{name: p{}, type: tip_position, body: stent, node: {}}}\n", k,
                       point(s.body.nodes[static_cast<std::size_t>(s.fixations[k].node)].position));
  const std::string text = fmt::format(R"(bodies:
  - name: stent
    beam: {{file: stent.vtu, E: 380000 MPa, G: 190000 MPa, joints: rigid}}
load_curves:
  ramp: [[0, 0], [1, 1]]
conditions:
  - {{name: fix, type: direction, body: stent, node: fixations, direction: file}}
  - {{name: push, type: point_force, body: stent, node: {}, value: [{:.17g}, {:.17g}, {:.17g}], curve: ramp}}
solver:
  time: {{start: 0, end: 1, dt: 0.25, dt_max: 0.25}}
  newton: {{max_iterations: 30, residual_tolerance: 1.0e-8, residual_absolute: 1.0e-9, increment_tolerance: 1.0e-12, line_search_steps: 0}}
  linear: {{type: direct}}
output: {{every: 4}}
qoi:
{})",
                                       point(X_axial), F[0], F[1], F[2], qoi);
  files::write_atomic(dir / "scene.yaml", text);
  SolveOptions o;
  o.output_dir = dir / "out";
  ASSERT_EQ(solve_scene(dir / "scene.yaml", o), 0);
  const Summary sum = Summary::read(dir / "out" / "summary.yaml");
  for (std::size_t k = 0; k < 5; ++k) {
    const auto v = std::get<std::vector<double>>(sum.qois().at("p" + std::to_string(k)).value);
    const Eigen::Vector3d u =
        Eigen::Vector3d(v[0], v[1], v[2]) - s.body.nodes[static_cast<std::size_t>(s.fixations[k].node)].position;
    const Eigen::Vector3d d = s.fixations[k].direction;
    if (s.fixations[k].axial) {
      const double in_plane = (u - u.dot(d) * d).norm();
      std::printf("axial fixation: d·u = %.2e mm, in-plane |u| = %.4e mm\n", u.dot(d), in_plane);
      EXPECT_LT(std::abs(u.dot(d)), 1e-12);
      EXPECT_GT(in_plane, 1e-3);  // it moves (the old "only along d" kept it at 0)
    } else {
      const double off_line = (u - u.dot(d) * d).norm();
      std::printf("radial fixation %zu: d·u = %.4e mm, off its line %.2e mm\n", k, u.dot(d), off_line);
      EXPECT_LT(off_line, 1e-12);
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace stentsim::solver
