// Placement on synthetic centerlines: narrowest site, ends, spline fit and
// its reproducibility from placement.yaml, weight adaptation for clearance,
// the errors for a too-large device and a balloon that does not fit, the
// lumen-surface clearance, and the three stages end to end.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <functional>
#include <numbers>

#include "common/error.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "device_gen/placement.hpp"
#include "device_gen/placement_file.hpp"
#include "device_gen/stages.hpp"
#include "device_gen/stent_mesh.hpp"
#include "synthetic_curves.hpp"

using namespace stentsim;
using namespace stentsim::device_gen;
namespace fs = std::filesystem;

namespace {

// A VMTK-like centerline polyline sampled every 0.05 mm.
MeshData centerline_mesh(const synthetic::Curve& f, double length, const std::function<double(double)>& radius,
                         const Eigen::Vector3d& normal = Eigen::Vector3d::UnitZ()) {
  MeshData m;
  DataArray r{1, {}}, s{1, {}}, n{3, {}};
  std::vector<std::int64_t> ids;
  const int count = static_cast<int>(std::lround(length / 0.05));
  for (int i = 0; i <= count; ++i) {
    const double si = length * i / count;
    m.points.push_back(f(si));
    r.values.push_back(radius(si));
    s.values.push_back(si);
    n.values.insert(n.values.end(), {normal.x(), normal.y(), normal.z()});
    ids.push_back(i);
  }
  m.add_cell(CellType::polyline, ids);
  m.point_data["MaximumInscribedSphereRadius"] = r;
  m.point_data["Abscissas"] = s;
  m.point_data["ParallelTransportNormals"] = n;
  return m;
}

synthetic::Curve straight_x() {
  return [](double s) { return Eigen::Vector3d(s, 0, 0); };
}

// A tube surface of radius r around a planar arc (in-plane normal z), N around.
MeshData tube_surface(const synthetic::Curve& f, double length, double r, int around = 48) {
  MeshData m;
  const int along = static_cast<int>(std::lround(length / 0.1));
  for (int j = 0; j <= along; ++j) {
    const double s = length * j / along, h = 1e-4;
    const Eigen::Vector3d t = (f(s + h) - f(s - h)).normalized();
    const Eigen::Vector3d n = Eigen::Vector3d::UnitZ(), b = t.cross(n);
    for (int i = 0; i < around; ++i) {
      const double a = 2 * std::numbers::pi * i / around;
      m.points.push_back(f(s) + r * (std::cos(a) * n + std::sin(a) * b));
    }
  }
  for (int j = 0; j < along; ++j)
    for (int i = 0; i < around; ++i) {
      const std::int64_t a = j * around + i, b = j * around + (i + 1) % around, c = a + around, d = b + around;
      m.add_cell(CellType::triangle, {a, b, d});
      m.add_cell(CellType::triangle, {a, d, c});
    }
  return m;
}

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("stentsim_device_gen_" + name + "_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST(DeviceGenPlacement, StraightDipFindsNarrowestSiteAndReproducesFromFile) {
  const auto radius = [](double s) { return 0.95 - 0.2 * std::exp(-std::pow((s - 12.0) / 1.5, 2)); };
  const Centerline cl = centerline_from_mesh(centerline_mesh(straight_x(), 30.0, radius), "synthetic.vtp");
  const Placement P = compute_placement(PlacementParams{}, cl, nullptr, BalloonDesign{}, StentDesign{});
  EXPECT_NEAR(P.site_abscissa, 12.0, 1e-9);
  EXPECT_EQ(P.site_chosen_by, "most severe lesion");
  EXPECT_NEAR(P.proximal_abscissa, 7.3, 1e-9);
  EXPECT_NEAR(P.distal_abscissa, 16.7, 1e-9);
  EXPECT_EQ(P.x.size(), 95u);
  EXPECT_NEAR(P.spacing, 0.1, 1e-12);
  for (const auto& f : P.fits) EXPECT_EQ(f.ier, -2);  // a line: the least-squares cubic, fp = 0 < zeta
  // Clearance: the straight spline is the centerline; the narrowest point is under the stent.
  EXPECT_NEAR(P.clearance_min, 0.75 - 0.635, 1e-9);
  EXPECT_EQ(P.weight_iterations, 0);
  // placement.yaml round trip: the same spline and axis.
  const fs::path dir = temp_dir("straight");
  write_placement_yaml(P, dir / "placement.yaml");
  const Placement Q = read_placement_yaml(dir / "placement.yaml");
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(Q.fits[static_cast<std::size_t>(k)].spline.knots, P.fits[static_cast<std::size_t>(k)].spline.knots);
    EXPECT_EQ(Q.fits[static_cast<std::size_t>(k)].spline.coefficients, P.fits[static_cast<std::size_t>(k)].spline.coefficients);
  }
  EXPECT_EQ(Q.weights, P.weights);
  const DeviceAxis axis = axis_from_placement(Q);
  EXPECT_LT((axis.position(4.7) - Eigen::Vector3d(12, 0, 0)).norm(), 1e-12);
  EXPECT_LT((axis.frame(2.0).tangent - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  fs::remove_all(dir);
}

TEST(DeviceGenPlacement, WeightsRaisedUntilClearanceHoldsOnWigglyArc) {
  // Arc of radius 10 mm with 0.15 mm in-plane wiggles in a lumen of radius
  // 0.70 mm: the zeta = 4 spline smooths the wiggles away and would leave
  // the lumen by more than the 0.065 mm of room around the crimped stent.
  const auto arc = synthetic::planar_arc(10.0);
  const synthetic::Curve wiggly = [&](double s) {
    const double h = 1e-5;
    const Eigen::Vector3d t = (arc(s + h) - arc(s - h)).normalized();
    return Eigen::Vector3d(arc(s) + 0.15 * std::sin(2.0 * s) * Eigen::Vector3d::UnitZ().cross(t));
  };
  const Centerline cl = centerline_from_mesh(centerline_mesh(wiggly, 20.0, [](double) { return 0.70; }), "wiggly.vtp");
  PlacementParams prm;
  prm.site_abscissa = 10.0;
  const Placement P = compute_placement(prm, cl, nullptr, BalloonDesign{}, StentDesign{});
  EXPECT_GT(P.weight_iterations, 0);
  EXPECT_GE(P.clearance_min, 0.0);
  double max_w = 0;
  for (double w : P.weights) max_w = std::max(max_w, w);
  EXPECT_GT(max_w, 1.0);
  for (int k = 0; k < 3; ++k) {
    const auto& f = P.fits[static_cast<std::size_t>(k)];
    // The smoothing condition holds with the final weights (or the cubic already meets it).
    EXPECT_TRUE(f.condition_met() || f.ier == -2) << "coordinate " << k << " ier " << f.ier;
    EXPECT_NEAR(fitpack::weighted_residual(f.spline, P.x, P.y[static_cast<std::size_t>(k)], P.weights), f.residual,
                1e-9 * std::max(1.0, f.residual));
  }
  // Without weight adaptation the same fit violates the clearance.
  prm.max_weight_iterations = 0;
  EXPECT_THROW(compute_placement(prm, cl, nullptr, BalloonDesign{}, StentDesign{}), InputError);
}

TEST(DeviceGenPlacement, ClearanceCheckCatchesTooLargeDevice) {
  const auto radius = [](double s) { return 0.95 - 0.35 * std::exp(-std::pow((s - 12.0) / 1.5, 2)); };  // 0.60 at the site
  const Centerline cl = centerline_from_mesh(centerline_mesh(straight_x(), 30.0, radius), "severe.vtp");
  try {
    compute_placement(PlacementParams{}, cl, nullptr, BalloonDesign{}, StentDesign{});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("severe.vtp"), std::string::npos) << msg;
    EXPECT_NE(msg.find("abscissa 12 mm"), std::string::npos) << msg;
    EXPECT_NE(msg.find("overlap 0.035 mm"), std::string::npos) << msg;
    EXPECT_NE(msg.find("crimped_diameter"), std::string::npos) << msg;
  }
  StentDesign smaller;
  smaller.crimped_diameter = 1.0;  // envelope 1.12 mm fits a 1.2 mm lumen
  const Placement P = compute_placement(PlacementParams{}, cl, nullptr, BalloonDesign{}, smaller);
  EXPECT_NEAR(P.clearance_min, 0.60 - 0.56, 1e-9);
}

TEST(DeviceGenPlacement, BalloonThatDoesNotFitSaysByHowMuch) {
  const auto radius = [](double s) { return 0.95 - 0.2 * std::exp(-std::pow((s - 3.0) / 1.0, 2)); };
  const Centerline cl = centerline_from_mesh(centerline_mesh(straight_x(), 30.0, radius), "short.vtp");
  try {
    compute_placement(PlacementParams{}, cl, nullptr, BalloonDesign{}, StentDesign{});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("reaches 1.7 mm beyond the proximal end"), std::string::npos) << msg;
  }
}

TEST(DeviceGenPlacement, LumenSurfaceClearanceAgreesWithInscribedSphere) {
  const auto arc = synthetic::planar_arc(10.0);
  const Centerline cl = centerline_from_mesh(centerline_mesh(arc, 20.0, [](double) { return 0.9; }), "arc.vtp");
  const MeshData lumen = tube_surface(arc, 20.0, 0.9);
  PlacementParams prm;
  prm.site_abscissa = 10.0;
  const Placement A = compute_placement(prm, cl, nullptr, BalloonDesign{}, StentDesign{});
  const Placement B = compute_placement(prm, cl, &lumen, BalloonDesign{}, StentDesign{});
  EXPECT_EQ(B.clearance_method, "lumen-surface");
  // 48-gon faceting of the tube: the inscribed distance is 0.9 cos(pi/48) = 0.8981.
  EXPECT_NEAR(B.clearance_min, A.clearance_min, 0.9 * (1 - std::cos(std::numbers::pi / 48)) + 1e-3);
  EXPECT_GT(B.clearance_min, 0.0);
  // The arc is planar: the balloon centerline stays in the plane z = 0.
  const DeviceAxis axis = axis_from_placement(B);
  for (double s = 0; s <= 9.4; s += 0.5) EXPECT_NEAR(axis.position(s).z(), 0.0, 1e-12);
}

TEST(DeviceGenPlacement, StagesEndToEndOnCurvedAndStraightScenes) {
  const auto arc = synthetic::planar_arc(10.0);
  const fs::path dir = temp_dir("stages");
  write_vtp((dir / "centerline.vtp").string(), centerline_mesh(arc, 24.0, [](double s) {
              return 0.95 - 0.19 * std::exp(-std::pow((s - 12.0) / 2.0, 2));  // case2-rca-like: 1.52 mm at the site
            }));
  write_vtp((dir / "lumen.vtp").string(), tube_surface(arc, 24.0, 0.95));
  StentDesign stent;
  stent.rings = 11;
  BalloonDesign balloon;
  balloon.length = 18.0;
  balloon.elements_around = 35;
  balloon.elements_along = 79;
  PlacementParams prm;
  Summary sp, sb, ss;
  // The tube surface is wider than the inscribed radius at the dip, so use the inscribed sphere here.
  run_placement_stage(prm, dir / "centerline.vtp", std::nullopt, balloon, stent, dir / "placement.yaml",
                      dir / "balloon_centerline.vtp", sp);
  run_balloon_stage(balloon, dir / "placement.yaml", dir / "balloon.vtu", sb);
  run_stent_stage(stent, dir / "placement.yaml", dir / "stent.vtu", ss);
  EXPECT_NEAR(std::get<double>(sp.qois().at("stenosis_abscissa").value), 12.0, 1e-9);
  EXPECT_GT(std::get<double>(sp.qois().at("placement_min_clearance").value), 0.0);
  EXPECT_EQ(std::get<double>(sb.qois().at("balloon_elements").value), 2765.0);
  EXPECT_EQ(std::get<double>(ss.qois().at("stent_beam_elements").value), 588.0);
  EXPECT_EQ(std::get<double>(ss.qois().at("stent_nodal_dofs").value), 8820.0);
  const MeshData stent_vtu = read_vtu((dir / "stent.vtu").string());
  int beams = 0, fixations = 0;
  for (double r : stent_vtu.cell_data.at("CellRole").values) {
    beams += static_cast<int>(r) == kStentBeam;
    fixations += static_cast<int>(r) == kStentRadialFixation || static_cast<int>(r) == kStentAxialFixation;
  }
  EXPECT_EQ(beams, 588);
  EXPECT_EQ(fixations, 4);  // curved: no axial fixation
  const MeshData polyline = read_vtp((dir / "balloon_centerline.vtp").string());
  EXPECT_NEAR(polyline.point_data.at("Abscissas").values.back(), 18.0, 1e-12);
  // A placement for another balloon length is refused.
  BalloonDesign other;
  EXPECT_THROW(run_balloon_stage(other, dir / "placement.yaml", dir / "b2.vtu", sb), InputError);
  // Straight scene: no placement.
  Summary s2, s3;
  run_balloon_stage(BalloonDesign{}, std::nullopt, dir / "balloon_straight.vtu", s2);
  run_stent_stage(StentDesign{}, std::nullopt, dir / "stent_straight.vtu", s3);
  EXPECT_EQ(std::get<double>(s2.qois().at("balloon_elements").value), 1276.0);
  EXPECT_EQ(std::get<double>(s3.qois().at("stent_beam_elements").value), 210.0);
  EXPECT_EQ(std::get<double>(s3.qois().at("stent_nodal_dofs").value), 3150.0);
  EXPECT_EQ(std::get<double>(s3.qois().at("stent_fixations").value), 5.0);
  fs::remove_all(dir);
}

TEST(DeviceGenPlacement, RejectsCenterlineWithoutVmtkArrays) {
  MeshData m = centerline_mesh(straight_x(), 10.0, [](double) { return 1.0; });
  m.point_data.erase("Abscissas");
  try {
    centerline_from_mesh(m, "c.vtp");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'Abscissas' is missing"), std::string::npos) << e.what();
  }
}
