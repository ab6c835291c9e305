// Observed order of the tube's inner-radius error (issue 11, "Error against
// run time"): the plane-strain coupled neo-Hooke tube of examples/tube_inflation.yaml
// (quarter annulus, one element layer with u_z = 0, follower pressure) against
// the shooting reference, on the mesh series of examples/studies/tube.yaml:
// 2x6, 4x12, 8x24 elements with the layer height 0.05, 0.025, 0.0125 mm.
// Expected orders: 2 +- 0.3 for hex8 and straight-sided tet10 (chordal
// geometry), 3 +- 0.4 for tet10 with midside nodes on the exact cylinders.
//
// The height must shrink with h (a self-similar series). With the height fixed
// at 0.05 mm the tets change shape along the series, from flat (0.3 x 0.21 x
// 0.05 mm prisms at 2x6) to tall (0.0375 x 0.026 x 0.05 at 16x48), and the
// tet10 error constant changes with them: the tet10-cylinder orders were 2.67,
// 2.47, 2.29 from 2x6 to 16x48 (the study's fit: 2.48); with the height scaled
// they are 2.86, 2.95, 2.98. hex8 does not notice (its discrete solution is
// z-independent: same errors to all digits). A degree-5 14-point volume rule
// for tet10 instead of the 4-point one changed neither series' trend (fixed:
// 2.76, 2.53, 2.32; scaled: 2.94, 3.00, 3.01), and a Newton tolerance of 1e-12
// none of the printed digits. The QoI is the study's: the mean deformed radius
// of the nodes on r = 0.8 (vertices, midpoints of axial edges and, for curved
// tet10, every midside node of the inner face).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/nonlinear/load_stepper.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "tests/solver/tube_reference.hpp"

namespace stentsim::solver {
namespace {

constexpr double kRi = 0.8, kRo = 1.4, kYoung = 1.0, kNu = 0.45, kPmax = 0.12;

std::string fmt_order(const std::vector<double>& e) {
  char buf[64];
  std::snprintf(buf, sizeof buf, ", order %.3f", std::log2(e[e.size() - 2] / e.back()));
  return buf;
}

struct Radii {
  double all = 0, vertex = 0, midside = 0;  // mean deformed radius of the nodes on r = kRi
};

// element: hex8, tet10 (straight midside nodes) or tet10c (midside nodes on the cylinders).
Radii solve_tube(const std::string& element, int nr, int nt, double height) {
  MeshData mesh = ring_sector_hex8(kRi, kRo, std::numbers::pi / 2, height, nr, nt, 1);
  mesh.point_data.clear();
  const std::size_t corners = mesh.points.size();
  if (element != "hex8") {
    mesh = hex8_to_tet4(mesh);
    mesh = element == "tet10c" ? tet4_to_tet10_cylindrical(mesh) : tet4_to_tet10(mesh);
  }
  Model model;
  SolidBodySpec spec;
  spec.name = "tube";
  spec.mesh = mesh;
  Material m;
  m.name = "neo-Hooke";
  m.matrix = CoupledNeoHooke::from_young_poisson(kYoung, kNu);
  spec.materials = {m};
  spec.cell_material.assign(mesh.num_cells(), 0);
  auto& body = model.add_term<SolidBody>(spec, model.dofs.allocate("tube", 3 * static_cast<GlobalDof>(mesh.points.size())));
  // Pressure faces as the study selects them: straight tet10 midside nodes lie
  // up to 0.007 mm inside r = 0.8 on the coarsest mesh.
  const double tol = 0.01;
  std::vector<fem::Face> inner;
  for (const auto& f : fem::boundary_faces(body.mesh())) {
    bool all = true;
    for (int i = 0; i < f.count; ++i) all = all && body.mesh().points[static_cast<std::size_t>(f.nodes[i])].head<2>().norm() < kRi + tol;
    if (all) inner.push_back(f);
  }
  model.add_term<FollowerPressure>("p", body, inner, kPmax, LoadCurve::ramp(0, 1));
  model.size_constraints();
  std::vector<std::size_t> inner_nodes;
  for (std::size_t i = 0; i < body.num_nodes(); ++i) {
    const Vec3 p = body.mesh().points[i];
    model.constraints.fix(body.dof(i, 2), [](double) { return 0.0; });
    if (std::abs(p.y()) < 1e-12) model.constraints.fix(body.dof(i, 1), [](double) { return 0.0; });
    if (std::abs(p.x()) < 1e-12) model.constraints.fix(body.dof(i, 0), [](double) { return 0.0; });
    if (std::abs(p.head<2>().norm() - kRi) < 1e-9) inner_nodes.push_back(i);
  }
  GlobalSystem sys(model.constraints);
  LinearSolverSettings ls;
  ls.type = LinearSolverType::direct;
  auto linear = make_linear_solver(ls);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
  StepperSettings st;  // hyperelastic: the end state does not depend on the path
  st.dt_initial = 0.25;
  st.dt_max = 0.25;
  NewtonSettings ns;  // as the scene; 1e-12 changes none of the printed digits
  ns.residual_tolerance = 1e-9;
  run_load_steps(model, sys, *linear, u, st, ns, [](const StepRecord&) {});
  Radii r;
  int nv = 0, nm = 0;
  for (auto i : inner_nodes) {
    const double ri = body.position(u, i).head<2>().norm();
    r.all += ri;
    (i < corners ? r.vertex : r.midside) += ri;
    (i < corners ? nv : nm) += 1;
  }
  r.all /= static_cast<double>(inner_nodes.size());
  if (nv) r.vertex /= nv;
  if (nm) r.midside /= nm;
  return r;
}

// Relative errors of the mean inner radius at p_max on the study's series.
std::vector<double> errors(const std::string& element) {
  const auto nh = CoupledNeoHooke::from_young_poisson(kYoung, kNu);
  const double ref = test::TubeReference{nh.c, nh.beta, kRi, kRo}.inner_radius(kPmax);
  std::vector<double> e;
  for (int nr : {2, 4, 8}) {
    const Radii r = solve_tube(element, nr, 3 * nr, 0.1 / nr);
    e.push_back(std::abs(r.all - ref) / ref);
    std::printf("%s %dx%d height %.4f mm: relative error %.4e (vertices alone %.4e", element.c_str(), nr, 3 * nr, 0.1 / nr,
                e.back(), std::abs(r.vertex - ref) / ref);
    if (r.midside > 0) std::printf(", midside nodes alone %.4e", std::abs(r.midside - ref) / ref);
    std::printf(")%s\n", e.size() > 1 ? fmt_order(e).c_str() : "");
    std::fflush(stdout);
  }
  return e;
}

void expect_orders(const std::vector<double>& e, double expected, double tolerance) {
  for (std::size_t i = 1; i < e.size(); ++i) {
    const double order = std::log2(e[i - 1] / e[i]);
    EXPECT_NEAR(order, expected, tolerance) << "refinement " << i;
  }
}

TEST(SolverTubeOrder, Hex8IsSecondOrder) { expect_orders(errors("hex8"), 2.0, 0.3); }

TEST(SolverTubeOrder, StraightTet10IsSecondOrder) { expect_orders(errors("tet10"), 2.0, 0.3); }

TEST(SolverTubeOrder, CylinderTet10IsThirdOrder) {
  const auto e = errors("tet10c");
  expect_orders(e, 3.0, 0.4);
  EXPECT_LT(e.back(), 2e-6);  // 1.27e-6 measured at 8x24
}

}  // namespace
}  // namespace stentsim::solver
