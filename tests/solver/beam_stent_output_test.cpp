// The stent stage's beam model loads as a beam body (issue 8: 210 elements,
// 3,150 nodal DOFs before joint coupling), and beam output for VTU.
#include "solver/beams/beam_output.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/stent_body.hpp"
#include "tests/solver/beam_test_bodies.hpp"
#include "tests/solver/beam_test_system.hpp"

#include "common/error.hpp"
#include "common/mesh_data.hpp"
#include "device_gen/device_axis.hpp"
#include "device_gen/stent_design.hpp"
#include "device_gen/stent_mesh.hpp"
#include "device_gen/stent_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

using namespace stentsim;
using namespace stentsim::solver;
using namespace stentsim::solver::beams;
using namespace stentsim::solver::beams::testing;

namespace {

MeshData four_ring_stent() {
  device_gen::StentDesign d;  // defaults: 4 rings, 8 crowns, 3 elements per strut/connector
  const device_gen::StentModel m = device_gen::build_stent(d, device_gen::DeviceAxis::straight(9.4));
  return device_gen::stent_to_mesh(m, d);
}

}  // namespace

TEST(BeamStent, FourRingStentLoadsAsBeamBody) {
  const MeshData mesh = four_ring_stent();
  const StentBeams s = stent_beams_from_mesh(mesh, 380000.0, 190000.0, "stent.vtu");
  EXPECT_EQ(s.body.elements.size(), 210u);
  EXPECT_EQ(beam_nodal_dof_count(s.body), 3150);  // the paper's count
  std::printf("stent: %zu elements, %zu nodes, %lld nodal DOFs, %zu joints, %zu fixations\n", s.body.elements.size(),
              s.body.nodes.size(), beam_nodal_dof_count(s.body), s.joints.size(), s.fixations.size());
  GlobalDof n = 0;
  const auto dofs = number_beam_dofs(s.body, 0, &n);
  EXPECT_EQ(n, 3150);
  BeamTerm beam("stent", s.body, dofs);
  // The reference state is stress-free: zero residual.
  TestSystem sys(n);
  sys.terms = {&beam};
  // Timing lives in bench_solver_beams, not here.
  const DenseAssembler a = sys.assemble(0.0);
  EXPECT_LT(a.R.cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GT(a.K.diagonal().minCoeff(), 0.0);  // every DOF has stiffness
  // the section: circular R = 0.06
  EXPECT_NEAR(s.body.section.radius, 0.06, 1e-15);
  EXPECT_NEAR(s.body.section.CM[0], s.body.section.CM[1], 1e-12);  // G I_T = E I for G = E/2
}

TEST(BeamStent, MalformedStentMeshIsReported) {
  MeshData mesh = four_ring_stent();
  mesh.point_data.erase("TriadE2");
  EXPECT_THROW(stent_beams_from_mesh(mesh, 1, 1, "x.vtu"), InputError);
  MeshData m2 = four_ring_stent();
  m2.point_data["TriadE1"].values[0] = 5.0;
  EXPECT_THROW(stent_beams_from_mesh(m2, 1, 1, "x.vtu"), InputError);
}

TEST(BeamOutput, SampledCenterlineAndResultants) {
  // A cantilever under a prescribed tip rotation (uniform bending moment
  // M = EI φ/L): output samples lie on the arc and carry ‖M_b‖ = M.
  const double L = 10.0, E = 1e4, phi = 1.0, R = 0.5;
  const BeamSection sec = BeamSection::circular(E, E / 2, R);
  const int n = 8;
  BeamBodyDefinition def = curve_body(straight_x(), L, n, sec);
  GlobalDof ndof = 0;
  auto dofs = number_beam_dofs(def, 0, &ndof);
  dofs[0].pos = dofs[0].rot = {-1, -1, -1};
  dofs[n].rot = {-1, -1, -1};
  BeamTerm beam("b", def, dofs);
  TestSystem sys(ndof);
  sys.terms = {&beam};
  beam.set_rotation(n, Eigen::Quaterniond(Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitZ())));
  sys.solve(1.0, 1e-12 * L);
  const int k = 6;
  const MeshData m = beam_output_mesh(beam, sys.u, k);
  ASSERT_EQ(m.points.size(), static_cast<std::size_t>(n * (k + 1)));
  ASSERT_EQ(m.num_cells(), static_cast<std::size_t>(n));
  const double I = std::numbers::pi * R * R * R * R / 4, M = E * I * phi / L;
  double worst_pos = 0, worst_m = 0;
  for (std::size_t p = 0; p < m.points.size(); ++p) {
    const Eigen::Vector3d c(0, L / phi, 0);  // arc centre
    worst_pos = std::max(worst_pos, std::abs((m.points[p] - c).norm() - L / phi));
    worst_m = std::max(worst_m, std::abs(m.point_data.at("BendingMoment").at(p) - M) / M);
    EXPECT_DOUBLE_EQ(m.point_data.at("Radius").at(p), R);
  }
  std::printf("output: max distance from the arc %.2e, max relative error of ‖M_b‖ %.2e\n", worst_pos, worst_m);
  EXPECT_LT(worst_pos, 1e-5);
  EXPECT_LT(worst_m, 1e-4);
  const double sigma = m.point_data.at("OuterFibreStress").at(3);
  EXPECT_NEAR(sigma, M * R / I, 1e-3 * M * R / I);
  // Writes and reads back as VTU.
  const std::string file = (std::filesystem::temp_directory_path() / "stentsim_beam_output_test.vtu").string();
  write_vtu(file, m);
  const MeshData back = read_vtu(file);
  EXPECT_EQ(back.points.size(), m.points.size());
  EXPECT_EQ(back.point_data.count("TriadD1"), 1u);
  std::filesystem::remove(file);
}

// The circular section of DESIGN.md §5 / issue 8: A = πR², I₂ = I₃ = πR⁴/4, I_T = πR⁴/2, shear areas k·A with
// Cowper's k = 6/7; resultant stiffnesses C_F = diag(EA, GA₂, GA₃), C_M = diag(GI_T, EI₂, EI₃).
TEST(BeamSection, CircularConstants) {
  const double E = 380000.0, G = 150000.0, R = 0.06, pi = std::numbers::pi;
  const BeamSection s = BeamSection::circular(E, G, R);
  const double A = pi * R * R, I = pi * std::pow(R, 4) / 4.0;
  EXPECT_NEAR(s.CF[0], E * A, 1e-12 * E * A);
  EXPECT_NEAR(s.CF[1], G * 6.0 / 7.0 * A, 1e-12 * E * A);
  EXPECT_NEAR(s.CF[2], G * 6.0 / 7.0 * A, 1e-12 * E * A);
  EXPECT_NEAR(s.CM[0], G * 2.0 * I, 1e-12 * E * I);
  EXPECT_NEAR(s.CM[1], E * I, 1e-12 * E * I);
  EXPECT_NEAR(s.CM[2], E * I, 1e-12 * E * I);
  EXPECT_DOUBLE_EQ(s.radius, R);
}
