// What the contact model leaves out (paper 2.5: no beam–beam contact, no
// self-contact) is detected and warned about: struts whose centerlines come
// closer than 2R (solver/app/contact/strut_overlap.hpp) and a contact surface
// folded through itself (solver/app/contact/surface_self_intersection.hpp).
// Each check sees a state that has the defect and one that does not.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "common/files.hpp"
#include "common/log.hpp"
#include "common/summary.hpp"
#include "solver/app/contact/strut_overlap.hpp"
#include "solver/app/contact/surface_self_intersection.hpp"
#include "solver/assembly/model.hpp"
#include "solver/contact/contact_surface.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/terms/solid_body.hpp"
#include "tests/solver/beam_test_bodies.hpp"
#include "tests/solver/neo_hooke_block.hpp"

namespace stentsim::solver {
namespace {

double qoi(const Summary& s, const std::string& key) { return std::get<double>(s.qois().at(key).value); }

/// The log lines written while `f` runs.
template <typename F>
std::string logged(const std::string& name, F&& f) {
  const auto file = std::filesystem::temp_directory_path() / ("stentsim_not_modelled_" + name + "_" + std::to_string(::getpid()) + ".log");
  std::filesystem::remove(file);
  log::set_file(file);
  f();
  log::set_file({});
  std::string text = std::filesystem::exists(file) ? files::read_text(file) : std::string();
  std::filesystem::remove(file);
  return text;
}

StepRecord at_time(double t) {
  StepRecord r;
  r.time = t;
  return r;
}

// A straight 6-element beam along x; its second half folded back over the
// first, 0.05 mm above it (closer than 2R = 0.12 mm), in a later step.
TEST(ContactNotModelled, StrutsCloserThanTwoRadiiAreWarnedAboutWithTheirDepth) {
  constexpr double R = 0.06;
  const auto def = beams::testing::curve_body(
      [](double t, Eigen::Vector3d& x, Eigen::Matrix3d& T) {
        x = Eigen::Vector3d(t, 0, 0);
        T.setIdentity();
      },
      6.0, 6, beams::BeamSection::circular(380000, 190000, R));
  Model model;
  GlobalDof count = 0;
  beams::number_beam_dofs(def, 0, &count);
  const GlobalDof first = model.dofs.allocate("beam", count);
  GlobalDof next = 0;
  const auto dofs = beams::number_beam_dofs(def, first, &next);
  auto& beam = model.add_term<beams::BeamTerm>("stent", def, dofs);
  auto check = make_strut_overlap_check(beam, R);

  Eigen::VectorXd u = Eigen::VectorXd::Zero(count);
  const std::string quiet = logged("overlap0", [&] { check->step(at_time(0.5), u); });
  EXPECT_EQ(quiet.find("overlap"), std::string::npos) << quiet;

  // Nodes at x > 3 mm moved by (−3, 0, 0.05): x in (3, 6] now lies over (0, 3].
  for (std::size_t n = 0; n < def.nodes.size(); ++n)
    if (def.nodes[n].position.x() > 3.0 + 1e-9 && dofs[n].pos[0] >= 0) {
      u[dofs[n].pos[0]] = -3.0;
      u[dofs[n].pos[2]] = 0.05;
    }
  const std::string warned = logged("overlap1", [&] { check->step(at_time(1.0), u); });
  EXPECT_NE(warned.find("beam 'stent'"), std::string::npos) << warned;
  EXPECT_NE(warned.find("overlap at t = 1"), std::string::npos) << warned;
  Summary s;
  check->summarize(s, RunEnd{});
  EXPECT_GT(qoi(s, "strut_overlap_points_max_stent"), 0.0);
  // At least the folded elements' 0.05 mm (the element joining the halves may cut closer).
  EXPECT_GE(qoi(s, "strut_overlap_depth_max_stent"), 2 * R - 0.05 - 1e-9);
  EXPECT_LE(qoi(s, "strut_overlap_depth_max_stent"), 2 * R);
}

// A 2 x 2 x 0.2 mm neo-Hooke slab (all its boundary faces, quad4, as the contact
// surface of a body called balloon); the top face's middle node pushed 0.1 mm
// below the bottom face.
TEST(ContactNotModelled, ASurfaceFoldedThroughItselfIsWarnedAboutWithItsFirstTime) {
  const auto block = make_neo_hooke_block(box_hex8(4, 4, 1, 2.0, 2.0, 0.2));
  const SolidBody& body = *block->body;
  const MeshData& mesh = body.mesh();
  const contact::ContactSurface surface("surface", body, fem::boundary_faces(body.mesh()));
  auto check = make_surface_self_intersection_check(surface, "balloon");

  Eigen::VectorXd u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(block->model.dofs.size()));
  const std::string quiet = logged("fold0", [&] {
    check->start(u, false);
    check->step(at_time(0.5), u);
  });
  EXPECT_EQ(quiet.find("intersects itself"), std::string::npos) << quiet;
  Summary none;
  check->summarize(none, RunEnd{});
  EXPECT_EQ(qoi(none, "self_intersection_pairs_max_balloon"), 0.0);
  EXPECT_EQ(qoi(none, "self_intersection_first_time_balloon"), -1.0);

  std::size_t middle = 0;
  for (std::size_t i = 0; i < mesh.points.size(); ++i)
    if ((mesh.points[i] - Vec3(1.0, 1.0, 0.2)).norm() < 1e-9) middle = i;
  u[body.dof(middle, 2)] = -0.3;  // z: 0.2 -> -0.1, through the bottom face z = 0
  const std::string warned = logged("fold1", [&] { check->step(at_time(0.75), u); });
  EXPECT_NE(warned.find("body 'balloon': its contact surface intersects itself at t = 0.75"), std::string::npos) << warned;
  check->step(at_time(1.0), Eigen::VectorXd::Zero(u.size()));  // unfolded again: the first time stays
  Summary s;
  check->summarize(s, RunEnd{});
  EXPECT_GT(qoi(s, "self_intersection_pairs_max_balloon"), 0.0);
  EXPECT_EQ(qoi(s, "self_intersection_first_time_balloon"), 0.75);
}

}  // namespace
}  // namespace stentsim::solver
