// Rigid joints by master–slave elimination (issue 9, DESIGN.md §8): DOF counts
// of the stent stage's models before and after coupling, conditions on slave
// nodes rejected, and a jointed frame that keeps its reference kink under a
// large load.
#include "common/error.hpp"
#include "device_gen/stent_design.hpp"
#include "device_gen/stent_mesh.hpp"
#include "device_gen/stent_model.hpp"
#include "solver/beams/beam_loads.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/rigid_joints.hpp"
#include "solver/beams/rotation.hpp"
#include "solver/beams/stent_body.hpp"
#include "tests/solver/beam_test_system.hpp"

#include <gtest/gtest.h>

using namespace stentsim;
using namespace stentsim::solver;
using namespace stentsim::solver::beams;
using namespace stentsim::solver::beams::testing;

namespace {

StentBeams stent(int rings) {
  device_gen::StentDesign d;
  d.rings = rings;
  const device_gen::StentModel m = device_gen::build_stent(d, device_gen::DeviceAxis::straight(d.length() + 3.4));
  return stent_beams_from_mesh(device_gen::stent_to_mesh(m, d), 380000.0, 190000.0, "stent.vtu");
}

}  // namespace

TEST(BeamJoint, StentDofCountsBeforeAndAfterCoupling) {
  for (int rings : {4, 11}) {
    const StentBeams s = stent(rings);
    const JointMap map = make_joint_map(s.body, s.joints, "stent.vtu");
    GlobalDof coupled = 0;
    const auto dofs = number_joined_beam_dofs(s.body, map, 0, &coupled);
    std::printf("stent %d rings: %zu elements, %zu joints, %lld nodal DOFs before coupling, %lld after\n", rings,
                s.body.elements.size(), s.joints.size(), beam_nodal_dof_count(s.body), static_cast<long long>(coupled));
    if (rings == 4) {
      EXPECT_EQ(s.body.elements.size(), 210u);
      EXPECT_EQ(beam_nodal_dof_count(s.body), 3150);
      EXPECT_EQ(coupled, 2694);
    } else {
      EXPECT_EQ(s.body.elements.size(), 588u);
      EXPECT_EQ(beam_nodal_dof_count(s.body), 8820);
    }
    // Every joint shares positions and rotations, never tangents.
    for (const auto& [a, b] : s.joints) {
      EXPECT_EQ(dofs[a].pos, dofs[b].pos);
      EXPECT_EQ(dofs[a].rot, dofs[b].rot);
      EXPECT_NE(dofs[a].tan, dofs[b].tan);
    }
    // A condition on a slave node names it.
    for (int n = 0; n < static_cast<int>(map.master.size()); ++n)
      if (map.is_slave(n)) {
        try {
          require_master_node(map, n, "scene.yaml: stent fixation");
          ADD_FAILURE() << "no error for slave node " << n;
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("node " + std::to_string(n)), std::string::npos) << e.what();
        }
        break;
      }
  }
}

TEST(BeamJoint, MismatchedJointPositionsAreInputErrors) {
  StentBeams s = stent(4);
  s.body.nodes[s.joints[0][1]].position.x() += 1e-3;
  EXPECT_THROW(make_joint_map(s.body, s.joints, "stent.vtu"), InputError);
}

TEST(BeamJoint, JointedLFrameKeepsItsKinkUnderLargeLoads) {
  // Two Hermite beams meeting at 90° at (1, 0, 0), each owning its end node.
  const BeamSection sec = BeamSection::from_values(1e4, 5e3, 1.0, 1.0, 1.0, 1.0 / 12, 1.0 / 12, 1.0 / 6);
  BeamBodyDefinition b;
  b.section = sec;
  auto node = [](Eigen::Vector3d x, Eigen::Matrix3d T) {
    BeamNode n;
    n.position = x;
    n.triad = Eigen::Quaterniond(T);
    return n;
  };
  const Eigen::Matrix3d Tx = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d Ty;
  Ty << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // d1 = +y
  b.nodes = {node({0, 0, 0}, Tx), node({1, 0, 0}, Tx), node({0.5, 0, 0}, Tx),
             node({1, 0, 0}, Ty), node({1, 1, 0}, Ty), node({1, 0.5, 0}, Ty)};
  b.elements = {{0, 1, 2}, {3, 4, 5}};
  const JointMap map = make_joint_map(b, {{1, 3}}, "frame");
  GlobalDof n = 0;
  auto dofs = number_joined_beam_dofs(b, map, 0, &n);
  EXPECT_EQ(n, 4 * 9 + 2 * 3 - 6);
  dofs[0].pos = dofs[0].rot = {-1, -1, -1};
  BeamTerm beam("frame", b, dofs);
  NodalLoadTerm force("tip force", dofs[4].pos, Eigen::Vector3d(0, 0, -200.0), [](double t) { return t; });
  NodalLoadTerm moment("tip moment", dofs[4].rot, Eigen::Vector3d(150.0, 0, 80.0), [](double t) { return t; });
  TestSystem sys(n);
  sys.terms = {&beam, &force, &moment};
  for (int s = 1; s <= 10; ++s) sys.solve(0.1 * s, 1e-12);
  const Eigen::Quaterniond ra = beam.rotation(1) * b.nodes[1].triad.conjugate();
  const Eigen::Quaterniond rb = beam.rotation(3) * b.nodes[3].triad.conjugate();
  const double rel = quat_log(ra * rb.conjugate()).norm();
  const double turned = quat_log(ra).norm();
  std::printf("L-frame: joint turned %.3f rad, relative rotation %.2e rad, tip displacement %.3f\n", turned, rel,
              (beam.position(sys.u, 4) - b.nodes[4].position).norm());
  EXPECT_GT(turned, 0.1);  // a large rotation at the joint
  EXPECT_LT(rel, 1e-10);
  EXPECT_LT((beam.position(sys.u, 1) - beam.position(sys.u, 3)).norm(), 1e-14);
  // The joint transmits the load: the rotated tangent of the second beam at
  // the joint is still perpendicular to the first beam's (the 90° kink).
  const Eigen::Matrix3d La = beam.rotation(1).toRotationMatrix(), Lb = beam.rotation(3).toRotationMatrix();
  EXPECT_NEAR(La.col(0).dot(Lb.col(0)), 0.0, 1e-10);
}
