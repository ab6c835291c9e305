// The balloon inflated alone (paper Section 2.3; DESIGN.md §5): its diameter
// against pressure follows the radial boundary-value problem of its own
// material. The balloon wall (inner radius 0.45 mm, outer 0.49 mm, one hex8
// through the 0.04 mm) of the `balloon` preset without its viscous branch is
// inflated by a follower pressure to 1.01 MPa in plane strain (quarter annulus,
// u_z = 0, symmetry planes). With nu = 0 a free tube keeps lambda_z = 1 with no
// axial stress (S_zz = 2c (1 - C_zz^-1) = 0), and the longitudinal family has
// I4 = 1, so plane strain is the free balloon between its ends.
//
// The reference is hgo_tube_reference.hpp with one layer: coupled neo-Hooke
// (c = E/4, beta = 0: Psi = c (I1 - 3 - 2 ln J)) and the circumferential family
// k1 = 1.5e-7 MPa, k2 = 0.35 (I4 = lambda_t^2). The thin-membrane curve
//   p(lambda) = H / (lambda R) [2c (lambda - 1/lambda) + 2 k1 lambda (lambda^2 - 1) exp(k2 (lambda^2 - 1)^2)]
// (lambda_r = 1 at nu = 0, so the thickness H stays; R the mid-surface radius)
// is printed beside it (3-19 % below the applied pressure: the thin membrane
// is no reference for a 0.04 mm wall on a 0.47 mm radius with an exponential
// family): the neo-Hooke part saturates at 2cH/R = 0.72 MPa and the
// circumferential family locks near lambda = 2.7, so the outer diameter at
// 1.01 MPa is about 2.6 mm. The pressure plateau in between amplifies any
// error in p into D by (lambda^2 - 1)/2.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>

#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/materials/presets.hpp"
#include "solver/nonlinear/load_stepper.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "tests/solver/hgo_tube_reference.hpp"

namespace stentsim::solver {
namespace {

constexpr double kRi = 0.45, kRo = 0.49, kPmax = 1.01;

Material elastic_balloon() {
  Material m = material_preset("balloon");
  m.viscous.reset();  // the reference is hyperelastic
  return m;
}

/// The preset's circumferential family (angle 0) as the reference's single layer.
test::HgoTubeReference reference() {
  const Material m = elastic_balloon();
  const FiberFamilySpec* circ = nullptr;
  for (const auto& f : m.fibers)
    if (f.angle_deg == 0.0) circ = &f;
  if (!circ) throw std::logic_error("balloon preset: no circumferential family");
  return test::HgoTubeReference(kRi, {test::HgoLayer{kRo, m.matrix->c, m.matrix->beta, circ->law.k1, circ->law.k2, 0.0, 1}});
}

/// Thin-membrane pressure at mid-surface hoop stretch lambda.
double thin_membrane_pressure(double lambda) {
  const Material m = elastic_balloon();
  const double c = m.matrix->c, H = kRo - kRi, R = 0.5 * (kRi + kRo);
  double fiber = 0;
  for (const auto& f : m.fibers)
    if (f.angle_deg == 0.0) {
      const double e = lambda * lambda - 1;
      fiber += 2 * f.law.k1 * lambda * e * std::exp(f.law.k2 * e * e);
    }
  return H / (lambda * R) * (2 * c * (lambda - 1 / lambda) + fiber);
}

struct Inflated {
  std::map<double, double> outer_diameter;  // pressure -> mean outer diameter (mm)
  int steps = 0, newton = 0, cuts = 0;
};

/// The quarter annulus with `nt` hex8 around (the balloon stage's 29 around the
/// full circle is about 7 per quarter), inflated to kPmax in steps of at most
/// dt_max (load factor), recorded at `pressures`.
Inflated inflate(int nt, double dt_max, const std::vector<double>& pressures) {
  MeshData mesh = ring_sector_hex8(kRi, kRo, std::numbers::pi / 2, 0.1, 1, nt, 1);
  SolidBodySpec spec;
  spec.name = "balloon";
  spec.materials = {elastic_balloon()};
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    Vec3 x = Vec3::Zero();
    for (auto n : mesh.cell(c)) x += mesh.points[static_cast<std::size_t>(n)];
    x /= 8.0;
    spec.cell_material.push_back(0);
    const Vec3 er = Vec3(x.x(), x.y(), 0).normalized();
    spec.cell_frames.push_back({er, Vec3::UnitZ().cross(er), Vec3::UnitZ()});
  }
  spec.mesh = std::move(mesh);
  Model model;
  auto& body = model.add_term<SolidBody>(spec, model.dofs.allocate("balloon", 3 * static_cast<GlobalDof>(spec.mesh.points.size())));
  std::vector<fem::Face> inner;
  for (const auto& f : fem::boundary_faces(body.mesh())) {
    bool all = true;
    for (int i = 0; i < f.count; ++i) all = all && body.mesh().points[static_cast<std::size_t>(f.nodes[i])].head<2>().norm() < kRi + 1e-9;
    if (all) inner.push_back(f);
  }
  const LoadCurve curve({{0, 0}, {1, kPmax}});
  model.add_term<FollowerPressure>("inflation", body, inner, 1.0, curve);
  model.size_constraints();
  std::vector<std::size_t> outer_nodes;
  for (std::size_t i = 0; i < body.num_nodes(); ++i) {
    const Vec3 p = body.mesh().points[i];
    model.constraints.fix(body.dof(i, 2), [](double) { return 0.0; });
    if (std::abs(p.y()) < 1e-12) model.constraints.fix(body.dof(i, 1), [](double) { return 0.0; });
    if (std::abs(p.x()) < 1e-12) model.constraints.fix(body.dof(i, 0), [](double) { return 0.0; });
    if (p.head<2>().norm() > kRo - 1e-9) outer_nodes.push_back(i);
  }
  GlobalSystem sys(model.constraints);
  LinearSolverSettings ls;
  ls.type = LinearSolverType::eigen_lu;
  auto linear = make_linear_solver(ls);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
  StepperSettings st;
  st.t_end = 1.0;
  st.dt_initial = dt_max;
  st.dt_max = dt_max;
  for (double p : pressures) st.stops.push_back(p / kPmax);
  Inflated out;
  run_load_steps(model, sys, *linear, u, st, {}, [&](const StepRecord& r) {
    ++out.steps;
    out.newton += r.newton_iterations;
    out.cuts += r.cuts;
    for (double p : pressures)
      if (std::abs(r.time - p / kPmax) < 1e-12) {
        double s = 0;
        for (auto i : outer_nodes) s += body.position(u, i).head<2>().norm();
        out.outer_diameter[p] = 2 * s / static_cast<double>(outer_nodes.size());
      }
  });
  return out;
}

const std::vector<double> kPressures{0.2, 0.4, 0.6, 0.7, 0.75, 0.8, 0.9, kPmax};

TEST(BalloonInflation, ReferenceSaturatesThenLocks) {
  const auto ref = reference();
  const double r1 = ref.inner_radius(kPmax), d1 = 2 * ref.radius_at(kPmax, r1, kRo);
  const double lambda_mid = ref.radius_at(kPmax, r1, 0.5 * (kRi + kRo)) / (0.5 * (kRi + kRo));
  std::printf("reference at %.2f MPa: outer diameter %.4f mm, mid-surface hoop stretch %.4f; thin membrane p(lambda) %.4f MPa\n",
              kPmax, d1, lambda_mid, thin_membrane_pressure(lambda_mid));
  // Paper 2.3 / issue 19: about 2.6 mm at 1.01 MPa, the circumferential family locking near 2.7.
  EXPECT_NEAR(d1, 2.6, 0.05);
  EXPECT_NEAR(lambda_mid, 2.7, 0.1);
  // The neo-Hooke part's saturation, 2cH/R: the thin-membrane curve approaches it
  // before the fibers take over (lambda = 2.2: neo-Hooke 0.57 MPa, fibers < 1e-3 MPa).
  const double c = elastic_balloon().matrix->c, sat = 2 * c * (kRo - kRi) / (0.5 * (kRi + kRo));
  EXPECT_NEAR(sat, 0.7234, 1e-3);
  EXPECT_NEAR(thin_membrane_pressure(2.2), sat * (1 - 1 / (2.2 * 2.2)), 1e-3);
  // The thin membrane is only an estimate of the thick wall (H/R = 0.085): the
  // exponential family loads the inner fibres, stretched more than the
  // mid-surface, so p(lambda_mid) falls below the applied pressure, most at the lock.
  for (double p : kPressures) {
    const double ri = ref.inner_radius(p);
    const double lm = ref.radius_at(p, ri, 0.5 * (kRi + kRo)) / (0.5 * (kRi + kRo));
    const double ratio = thin_membrane_pressure(lm) / p;
    std::printf("  p %.3f MPa: thick-wall outer diameter %.5f mm, thin membrane p(lambda_mid) / p = %.4f\n", p,
                2 * ref.radius_at(p, ri, kRo), ratio);
    EXPECT_GT(ratio, 0.8) << "p = " << p;
    EXPECT_LT(ratio, 1.0) << "p = " << p;
  }
}

TEST(BalloonInflation, OuterDiameterFollowsItsMaterialsCurveWithin1Percent) {
  const auto ref = reference();
  const Inflated fe = inflate(8, 0.05, kPressures);
  std::printf("FE quarter annulus, 8 hex8 around: %d steps, %d Newton iterations, %d cuts\n", fe.steps, fe.newton, fe.cuts);
  std::printf("  p [MPa]   D_FE [mm]   D_ref [mm]   D error   thin-membrane p(lambda_FE) / p\n");
  ASSERT_EQ(fe.outer_diameter.size(), kPressures.size());
  for (double p : kPressures) {
    const double d = fe.outer_diameter.at(p), dref = 2 * ref.radius_at(p, ref.inner_radius(p), kRo);
    const double lambda_fe = (0.5 * d - 0.5 * (kRo - kRi)) / (0.5 * (kRi + kRo));
    std::printf("  %7.3f   %9.5f   %10.5f   %+7.3f %%   %.4f\n", p, d, dref, 100 * (d / dref - 1), thin_membrane_pressure(lambda_fe) / p);
    EXPECT_NEAR(d / dref, 1.0, 0.01) << "p = " << p;
  }
  // The largest error sits on the plateau's knee (0.6 MPa), where D reacts
  // most to the polygon's chord error: a finer ring shrinks it.
  const Inflated fine = inflate(16, 0.05, {0.6});
  const double dref = 2 * ref.radius_at(0.6, ref.inner_radius(0.6), kRo);
  const double e8 = std::abs(fe.outer_diameter.at(0.6) / dref - 1), e16 = std::abs(fine.outer_diameter.at(0.6) / dref - 1);
  std::printf("  at 0.6 MPa: |D error| %.4f %% with 8 around, %.4f %% with 16\n", 100 * e8, 100 * e16);
  EXPECT_LT(e16, 0.5 * e8);
}

}  // namespace
}  // namespace stentsim::solver
