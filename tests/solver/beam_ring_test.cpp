// Stent ring expansion (issue 9): one ring of the stent stage (16 struts),
// elasto-plastic beams (App. C preset), rigid crown joints by master–slave
// elimination. Crowns are pushed radially 0 → 0.725 mm (strut-centerline
// diameter 1.15 → 2.6 mm) in 20 steps with zero circumferential displacement
// (mirror planes) and one crown fixed axially; then the radial conditions
// become point forces equal to their last reactions, ramped to zero in 10
// steps. Reports D_max, D_end and the recoil.
#include "device_gen/stent_design.hpp"
#include "device_gen/stent_mesh.hpp"
#include "device_gen/stent_model.hpp"
#include "solver/assembly/global_system.hpp"
#include "solver/assembly/model.hpp"
#include "solver/beams/beam_loads.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/plastic_bending.hpp"
#include "solver/beams/rigid_joints.hpp"
#include "solver/beams/rotation.hpp"
#include "solver/beams/stent_body.hpp"
#include "solver/linalg/linear_solver.hpp"
#include "solver/nonlinear/newton.hpp"
#include "tests/solver/beam_test_system.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <set>

using namespace stentsim;
using namespace stentsim::solver;
using namespace stentsim::solver::beams;
using namespace stentsim::solver::beams::testing;

namespace {

constexpr double kPush = 0.725;  // radial crown displacement [mm]
constexpr int kExpandSteps = 20, kReleaseSteps = 10;

struct RingResult {
  double D0 = 0, D_max = 0, D_end = 0, recoil_percent = 0;
  double peak_spread = 0, valley_spread = 0;  // max relative radius spread after release
  double max_Mb_peak = 0, max_Mb_end = 0;
  bool max_Mb_next_to_crown = false;
  double max_crown_reaction_end = 0;  // N
  double external_work = 0, stored_energy = 0, plastic_work = 0;
  double max_joint_rotation_error = 0;
  int max_newton = 0;
};

struct Crown {
  int node;  // master
  Eigen::Vector3d er, ephi;
  bool peak;
};

RingResult expand_ring(int elements_per_strut) {
  device_gen::StentDesign d;
  d.rings = 1;
  d.elements_per_strut = elements_per_strut;
  const device_gen::StentModel m = device_gen::build_stent(d, device_gen::DeviceAxis::straight(d.length() + 3.0));
  StentBeams s = stent_beams_from_mesh(device_gen::stent_to_mesh(m, d), 380000.0, 190000.0, "ring");
  const PlasticBendingLaw law = PlasticBendingLaw::stent_preset();
  s.body.section = BeamSection::circular_plastic(law);
  EXPECT_EQ(s.body.elements.size(), static_cast<std::size_t>(16 * elements_per_strut));
  const JointMap joints = make_joint_map(s.body, s.joints, "ring");
  GlobalDof n = 0;
  const auto dofs = number_joined_beam_dofs(s.body, joints, 0, &n);
  BeamTerm beam("ring", s.body, dofs);

  std::vector<Crown> crowns;
  std::set<int> masters;
  double zc = 0.0;
  for (const auto& j : s.joints) masters.insert(joints.master[j[0]]);
  for (int c : masters) zc += s.body.nodes[c].position.z() / masters.size();
  for (int c : masters) {
    const Eigen::Vector3d X = s.body.nodes[c].position;
    const Eigen::Vector3d er = Eigen::Vector3d(X.x(), X.y(), 0).normalized();
    crowns.push_back({c, er, Eigen::Vector3d::UnitZ().cross(er), X.z() > zc});
  }
  EXPECT_EQ(crowns.size(), 16u);

  RingResult r;
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  auto radius = [&](const Crown& c) {
    const Eigen::Vector3d x = beam.position(u, c.node);
    return std::hypot(x.x(), x.y());
  };
  for (const Crown& c : crowns) r.D0 += 2.0 * radius(c) / crowns.size();

  LinearSolverSettings ls;
  ls.type = "eigen_lu";
  auto linear = make_linear_solver(ls);
  NewtonSettings ns;
  ns.max_iterations = 30;
  ns.residual_tolerance = 1e-12;
  ns.residual_absolute = 1e-11;
  ns.increment_tolerance = 1e-12;
  ns.line_search_steps = 0;

  // The crown forces at the end of expansion, for the release phase.
  std::vector<std::unique_ptr<NodalLoadTerm>> release_loads;
  double release_scale = 1.0;
  auto crown_forces = [&]() {  // internal forces at the crowns' position DOFs (= reactions)
    DenseAssembler a(n);
    beam.assemble(SystemState{u, 0.0, 0.0}, a);
    std::vector<Eigen::Vector3d> f;
    for (const Crown& c : crowns) f.push_back(Eigen::Vector3d(a.R[dofs[c.node].pos[0]], a.R[dofs[c.node].pos[1]],
                                                               a.R[dofs[c.node].pos[2]]));
    return f;
  };
  auto max_bending = [&](bool* next_to_crown) {
    double best = 0.0;
    for (std::size_t e = 0; e < s.body.elements.size(); ++e) {
      const auto st = beam.section_states(u, e);
      for (std::size_t g = 0; g < st.size(); ++g) {
        const double mb = st[g].M.tail<2>().norm();
        if (mb > best) {
          best = mb;
          if (next_to_crown) {
            // next to a crown: the element's end node nearest this Gauss point is a joint node
            const BeamElement& el = s.body.elements[e];
            const int end = st[g].xi < 0 ? el.a : el.b;
            *next_to_crown = masters.count(joints.master[end]) > 0;
          }
        }
      }
    }
    return best;
  };

  auto run_phase = [&](bool expansion, int steps, double t0) {
    Model model;
    model.dofs.allocate("ring", n);
    model.size_constraints();
    model.add_term<ForwardTerm>(&beam);
    for (std::size_t k = 0; k < crowns.size(); ++k) {
      const Crown& c = crowns[k];
      const GlobalDof p = dofs[c.node].pos[0];
      Mat3 Q;
      Q.col(0) = c.er, Q.col(1) = c.ephi, Q.col(2) = Eigen::Vector3d::UnitZ();
      model.constraints.set_frame(p, Q);
      if (expansion) model.constraints.fix(p, [t0, steps](double t) { return kPush * (t - t0) / steps; });
      model.constraints.fix(p + 1, [](double) { return 0.0; });
      if (k == 0) model.constraints.fix(p + 2, [](double) { return 0.0; });
    }
    if (!expansion) {
      const auto f = crown_forces();
      release_loads.clear();
      for (std::size_t k = 0; k < crowns.size(); ++k) {
        const Eigen::Vector3d fr = crowns[k].er.dot(f[k]) * crowns[k].er;
        release_loads.push_back(std::make_unique<NodalLoadTerm>("release", dofs[crowns[k].node].pos, fr,
                                                                [&release_scale](double) { return release_scale; }));
        model.add_term<ForwardTerm>(release_loads.back().get());
      }
    }
    GlobalSystem system(model.constraints);
    for (int step = 1; step <= steps; ++step) {
      const double t = t0 + step;
      const Eigen::VectorXd u_old = u;
      const auto f_old = crown_forces();
      if (!expansion) release_scale = 1.0 - static_cast<double>(step) / steps;
      const NewtonResult nr = newton_step(model, system, *linear, u, t, 1.0, ns);
      if (!nr.converged) throw std::runtime_error("ring Newton: " + nr.failure + " at step " + std::to_string(step));
      // Assemble once more at the converged state so that the committed
      // history is the converged one, then commit.
      const auto f_new = crown_forces();
      model.commit();
      r.max_newton = std::max(r.max_newton, nr.iterations);
      // External work at the crowns, trapezoidal (the forces the supports or
      // the release loads exert equal the internal crown forces).
      for (std::size_t k = 0; k < crowns.size(); ++k) {
        const GlobalDof p = dofs[crowns[k].node].pos[0];
        const Eigen::Vector3d du = u.segment<3>(p) - u_old.segment<3>(p);
        r.external_work += 0.5 * (f_old[k] + f_new[k]).dot(du);
      }
    }
  };

  run_phase(true, kExpandSteps, 0.0);
  for (const Crown& c : crowns) r.D_max += 2.0 * radius(c) / crowns.size();
  r.max_Mb_peak = max_bending(&r.max_Mb_next_to_crown);
  run_phase(false, kReleaseSteps, kExpandSteps);

  double pmin = 1e300, pmax = 0, vmin = 1e300, vmax = 0;
  for (const Crown& c : crowns) {
    const double rad = radius(c);
    r.D_end += 2.0 * rad / crowns.size();
    (c.peak ? pmin : vmin) = std::min(c.peak ? pmin : vmin, rad);
    (c.peak ? pmax : vmax) = std::max(c.peak ? pmax : vmax, rad);
  }
  r.peak_spread = (pmax - pmin) / pmax;
  r.valley_spread = (vmax - vmin) / vmax;
  r.recoil_percent = 100.0 * (r.D_max - r.D_end) / r.D_max;
  r.max_Mb_end = max_bending(nullptr);
  for (const auto& f : crown_forces()) r.max_crown_reaction_end = std::max(r.max_crown_reaction_end, f.norm());
  r.stored_energy = beam.energy(u);
  r.plastic_work = beam.plastic_work();
  for (const auto& [a, b] : s.joints) {
    const Eigen::Quaterniond ra = beam.rotation(a) * s.body.nodes[a].triad.conjugate();
    const Eigen::Quaterniond rb = beam.rotation(b) * s.body.nodes[b].triad.conjugate();
    r.max_joint_rotation_error = std::max(r.max_joint_rotation_error, quat_log(ra * rb.conjugate()).norm());
  }
  return r;
}

void check_and_report(int eps) {
  const RingResult r = expand_ring(eps);
  const double balance = std::abs(r.external_work - r.stored_energy - r.plastic_work) / r.external_work;
  std::printf(
      "ring %d el/strut: D0 %.6f, D_max %.6f, D_end %.6f mm, recoil %.3f %%; max |M_b| %.4f (peak) %.4f (end) N·mm; "
      "crown reaction after release %.2e N; W_ext %.6e = stored %.6e + plastic %.6e (balance error %.3e); "
      "peak/valley radius spread %.1e/%.1e; joint rotation error %.1e rad; max Newton iterations %d\n",
      eps, r.D0, r.D_max, r.D_end, r.recoil_percent, r.max_Mb_peak, r.max_Mb_end, r.max_crown_reaction_end,
      r.external_work, r.stored_energy, r.plastic_work, balance, r.peak_spread, r.valley_spread,
      r.max_joint_rotation_error, r.max_newton);
  EXPECT_NEAR(r.D0, 1.15, 1e-6);
  EXPECT_NEAR(r.D_max, 2.6, 1e-9);
  EXPECT_LT(r.D_end, r.D_max);
  EXPECT_GT(r.D_end, r.D0);  // plastic set: the ring stays open
  EXPECT_LT(r.peak_spread, 1e-6);
  EXPECT_LT(r.valley_spread, 1e-6);
  EXPECT_GT(r.max_Mb_peak, PlasticBendingLaw::stent_preset().M_y0);
  EXPECT_TRUE(r.max_Mb_next_to_crown);
  EXPECT_LT(r.max_crown_reaction_end, 1e-8);
  EXPECT_LT(balance, 0.01);
  EXPECT_LT(r.max_joint_rotation_error, 1e-10);
}

}  // namespace

TEST(BeamRing, ExpansionAndRecoilThreeElementsPerStrut) { check_and_report(3); }
TEST(BeamRing, ExpansionAndRecoilSixElementsPerStrut) { check_and_report(6); }
