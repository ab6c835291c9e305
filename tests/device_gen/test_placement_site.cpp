// Placement against a lumen with a known stenosis (issue 4 leftovers):
// 1. a curved vessel (arc of radius 10 mm) with a Gaussian stenosis at a
//    known abscissa: the balloon midpoint lies at the stenosis, its ends at
//    +- length/2 of arc length, and its outer surface inside the lumen with a
//    clearance computed here independently (brute-force point-to-triangle
//    distances, not device_gen/surface_distance);
// 2. a tapering vessel whose raw narrowest radius is the healthy distal end
//    but whose stenosis is mid-vessel: the placement finds the stenosis by
//    the taper-discounting rule shared with the segmentation ROI
//    (common/stenosis_site.hpp) and reports its percent diameter.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <numbers>
#include <unistd.h>

#include "common/error.hpp"
#include "common/mesh_data.hpp"
#include "common/stenosis_site.hpp"
#include "common/summary.hpp"
#include "device_gen/placement.hpp"
#include "device_gen/placement_file.hpp"
#include "device_gen/stages.hpp"
#include "synthetic_curves.hpp"

using namespace stentsim;
using namespace stentsim::device_gen;
namespace fs = std::filesystem;
using Eigen::Vector3d;

namespace {

constexpr double kSample = 0.05;  // centerline sampling (mm), as VMTK resampled

MeshData centerline_mesh(const synthetic::Curve& f, double length, const std::function<double(double)>& radius) {
  MeshData m;
  DataArray r{1, {}}, s{1, {}}, n{3, {}};
  std::vector<std::int64_t> ids;
  const int count = static_cast<int>(std::lround(length / kSample));
  for (int i = 0; i <= count; ++i) {
    const double si = length * i / count;
    m.points.push_back(f(si));
    r.values.push_back(radius(si));
    s.values.push_back(si);
    n.values.insert(n.values.end(), {0.0, 0.0, 1.0});
    ids.push_back(i);
  }
  m.add_cell(CellType::polyline, ids);
  m.point_data["MaximumInscribedSphereRadius"] = r;
  m.point_data["Abscissas"] = s;
  m.point_data["ParallelTransportNormals"] = n;
  return m;
}

// Lumen of varying radius around a planar curve (in-plane normal z): rings
// every 0.1 mm, `around` vertices per ring.
MeshData lumen_surface(const synthetic::Curve& f, double length, const std::function<double(double)>& radius,
                       int around = 48) {
  MeshData m;
  const int along = static_cast<int>(std::lround(length / 0.1));
  for (int j = 0; j <= along; ++j) {
    const double s = length * j / along, h = 1e-5;
    const Vector3d t = (f(s + h) - f(s - h)).normalized();
    const Vector3d n = Vector3d::UnitZ(), b = t.cross(n);
    for (int i = 0; i < around; ++i) {
      const double a = 2 * std::numbers::pi * i / around;
      m.points.push_back(f(s) + radius(s) * (std::cos(a) * n + std::sin(a) * b));
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

// Distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
double point_triangle_distance(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.norm();
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

double distance_to_surface(const MeshData& m, const Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < m.num_cells(); ++k) {
    const std::int64_t* v = m.connectivity.data() + m.cell_offsets[k];
    const Vector3d& a = m.points[static_cast<std::size_t>(v[0])];
    // Only triangles near p can be nearest: cheap reject by the first vertex (edges < 0.2 mm).
    if ((a - p).norm() - 0.2 > best) continue;
    best = std::min(best, point_triangle_distance(p, a, m.points[static_cast<std::size_t>(v[1])],
                                                  m.points[static_cast<std::size_t>(v[2])]));
  }
  return best;
}

// Arc length of the spline curve over [a, b] (composite 5-point Gauss-Legendre).
double spline_length(const SplineCurve& c, double a, double b, int panels = 400) {
  const double xg[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
  const double wg[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891,
                        0.2369268850561891};
  double total = 0;
  const double h = (b - a) / panels;
  for (int k = 0; k < panels; ++k)
    for (int g = 0; g < 5; ++g) total += 0.5 * h * wg[g] * c.derivative(a + h * (k + 0.5 + 0.5 * xg[g]), 1).norm();
  return total;
}

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("stentsim_device_site_" + name + "_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST(DeviceGenPlacementSite, BalloonCentredAtKnownStenosisInsideCurvedLumen) {
  // Arc R = 10 mm, 25 mm long; healthy radius 1.0 mm, Gaussian stenosis to
  // 0.75 mm (25 % in diameter) at s* = 12.3 mm, a centerline sample.
  const double s_true = 12.3, length = 25.0;
  const auto arc = synthetic::planar_arc(10.0);
  const auto radius = [&](double s) { return 1.0 - 0.25 * std::exp(-std::pow((s - s_true) / 1.5, 2)); };
  const Centerline cl = centerline_from_mesh(centerline_mesh(arc, length, radius), "arc_stenosis.vtp");
  const MeshData lumen = lumen_surface(arc, length, radius);
  const BalloonDesign balloon;  // 9.4 mm, outer diameter 0.98 mm
  const StentDesign stent;      // crimped envelope 1.27 mm over 6 mm
  const Placement P = compute_placement(PlacementParams{}, cl, &lumen, balloon, stent);
  const double L = balloon.length;

  // Site: the smoothed radius of a symmetric dip on a constant healthy radius
  // is smallest at the dip's centre, and the site is chosen among centerline
  // samples: it must be s* within half a sample spacing.
  EXPECT_EQ(P.site_chosen_by, "most severe lesion");
  EXPECT_NEAR(P.site_abscissa, s_true, 0.5 * kSample);
  // Reference (healthy) radius 1.0 (the upper-envelope line drops the dip);
  // percent stenosis of the inscribed radius at the site: 25 %.
  // The envelope fit keeps samples down to 2 % below the line, so the
  // Gaussian's tails (deficit < 0.02 beyond 2.4 mm from the site) pull r_ref
  // a little below 1.0: measured 0.9990; allowed 2e-3.
  EXPECT_NEAR(P.site_reference_radius, 1.0, 2e-3);
  EXPECT_NEAR(P.reference_taper, 0.0, 1e-4);
  // With r_ref within 2e-3: d(%DS) = 100 (r / r_ref) dr_ref / r_ref < 100 * 0.76 * 2e-3 = 0.15 %.
  EXPECT_NEAR(P.percent_diameter_stenosis(), 25.0, 0.15);

  // Ends at +- L/2 of arc length along the centerline.
  EXPECT_NEAR(P.proximal_abscissa, P.site_abscissa - 0.5 * L, 1e-12);
  EXPECT_NEAR(P.distal_abscissa, P.site_abscissa + 0.5 * L, 1e-12);
  // The balloon centerline spline itself: its ends and midpoint lie on the
  // vessel axis at those abscissae, up to the smoothing residual (each point's
  // weighted residual is bounded by sqrt(fp) per coordinate).
  const SplineCurve curve = P.curve();
  double bound = 0;
  for (const auto& f : P.fits) bound += f.residual;
  bound = std::sqrt(bound) / *std::min_element(P.weights.begin(), P.weights.end()) + 1e-9;
  const double d0 = (curve.position(0.0) - arc(P.proximal_abscissa)).norm();
  const double dm = (curve.position(0.5 * L) - arc(s_true)).norm();
  const double d1 = (curve.position(L) - arc(P.distal_abscissa)).norm();
  const double half0 = spline_length(curve, 0.0, 0.5 * L), half1 = spline_length(curve, 0.5 * L, L);
  // The device axis (what the balloon and stent meshes are built along)
  // measures true arc length of the spline from the midpoint: its ends are
  // L/2 of arc length either side of the stenosis.
  const DeviceAxis axis = axis_from_placement(P);
  const double a0 = (axis.position(0.0) - arc(s_true - 0.5 * L)).norm();
  const double am = (axis.position(0.5 * L) - arc(s_true)).norm();
  const double a1 = (axis.position(L) - arc(s_true + 0.5 * L)).norm();
  std::printf("site %.4f (true %.4f), %%DS %.3f (r_ref %.5f), spline ends off-axis %.2e %.2e mm, midpoint %.2e mm "
              "(bound %.2e); spline half lengths %.5f %.5f (L/2 %.2f); device axis ends/midpoint from the true points "
              "%.2e %.2e %.2e mm\n",
              P.site_abscissa, s_true, P.percent_diameter_stenosis(), P.site_reference_radius, d0, d1, dm, bound, half0,
              half1, 0.5 * L, a0, a1, am);
  EXPECT_LT(d0, bound);
  EXPECT_LT(d1, bound);
  EXPECT_LT(dm, bound + std::abs(P.site_abscissa - s_true));
  // Each spline end may sit up to `bound` off its axis point: each half's
  // length is L/2 within that.
  EXPECT_NEAR(half0, 0.5 * L, bound);
  EXPECT_NEAR(half1, 0.5 * L, bound);
  EXPECT_LT(am, bound + std::abs(P.site_abscissa - s_true));
  EXPECT_LT(a0, bound + std::abs(P.site_abscissa - s_true));
  EXPECT_LT(a1, bound + std::abs(P.site_abscissa - s_true));
  EXPECT_NEAR(axis.length(), L, 1e-12);

  // Clearance, independently: distance from samples of the balloon centerline
  // to the lumen triangles minus the device radius (the crimped stent over
  // its length, the balloon elsewhere) and minus the balloon radius alone.
  double clearance_envelope = std::numeric_limits<double>::infinity(), clearance_balloon = clearance_envelope;
  for (int i = 0; i <= 470; ++i) {
    const double x = L * i / 470.0;
    const Vector3d p = curve.position(x);
    // Inside: the lumen is a tube around the arc (centre (0, 10, 0)).
    const double off_axis = std::abs((p - Vector3d(0, 10, 0)).norm() - 10.0);
    ASSERT_LT(off_axis, radius(P.proximal_abscissa + x)) << "balloon centerline outside the lumen at x = " << x;
    const double d = distance_to_surface(lumen, p);
    clearance_balloon = std::min(clearance_balloon, d - 0.5 * balloon.outer_diameter);
    const bool on_stent = std::abs(x - 0.5 * L) <= 0.5 * stent.length();
    clearance_envelope =
        std::min(clearance_envelope, d - (on_stent ? 0.5 * stent.envelope_diameter() : 0.5 * balloon.outer_diameter));
  }
  std::printf("clearance: reported %.5f mm (%s), independent envelope %.5f mm, balloon alone %.5f mm\n",
              P.clearance_min, P.clearance_method.c_str(), clearance_envelope, clearance_balloon);
  EXPECT_EQ(P.clearance_method, "lumen-surface");
  EXPECT_GT(P.clearance_min, 0.0);
  EXPECT_GT(clearance_envelope, 0.0);
  EXPECT_GT(clearance_balloon, clearance_envelope);
  // The reported minimum is taken at the 0.1 mm fit samples, ours every
  // 0.02 mm: near the minimum (the stenosis, where the radius is flat) they
  // differ by second-order terms only.
  EXPECT_NEAR(P.clearance_min, clearance_envelope, 2e-3);
}

TEST(DeviceGenPlacementSite, TaperingVesselStenosisMidVesselNotTheDistalEnd) {
  // Straight vessel, 30 mm: healthy radius 1.6 - 0.03 s (1.6 -> 0.7 mm), a
  // 30 % diameter cosine stenosis 4 mm long at s = 12 mm (0.868 mm). The raw
  // narrowest (smoothed, ends excluded) is the healthy distal end: 0.73 mm
  // at 29 mm.
  const double s_true = 12.0, length = 30.0;
  const auto healthy = [](double s) { return 1.6 - 0.03 * s; };
  const auto radius = [&](double s) {
    const double d = std::abs(s - s_true);
    return healthy(s) * (1 - (d < 2.0 ? 0.30 * 0.5 * (1 + std::cos(std::numbers::pi * d / 2.0)) : 0.0));
  };
  const auto straight = [](double s) { return Vector3d(s, 0, 0); };
  const PlacementParams prm;
  const Centerline cl = centerline_from_mesh(centerline_mesh(straight, length, radius), "tapered.vtp");
  // The test can fail: the raw rule picks the distal end, where a 9.4 mm balloon does not even fit.
  double raw_min = std::numeric_limits<double>::infinity(), raw_at = 0;
  for (double s : cl.abscissa)
    if (s >= 1.0 && s <= length - 1.0 && cl.smoothed_radius(s, prm.radius_window) < raw_min)
      raw_min = cl.smoothed_radius(s, prm.radius_window), raw_at = s;
  EXPECT_NEAR(raw_at, length - 1.0, 1e-9);

  const Placement P = compute_placement(prm, cl, nullptr, BalloonDesign{}, StentDesign{});
  // Expected: the lesion's 30 % (inscribed radius at the site against the
  // reference line, which is healthy(s)).
  const double expected_pct = 30.0;
  std::printf("raw narrowest %.3f mm at %.2f mm; taper-discounted site %.3f mm, r %.4f, r_ref %.4f (true %.4f), "
              "slope %.5f, %%DS %.3f (expected %.3f, true 30)\n",
              raw_min, raw_at, P.site_abscissa, P.site_smoothed_radius, P.site_reference_radius, healthy(s_true),
              P.reference_taper, P.percent_diameter_stenosis(), expected_pct);
  EXPECT_NEAR(P.site_abscissa, s_true, 0.5 * kSample);
  EXPECT_NEAR(P.reference_taper, -0.03, 1e-4);
  EXPECT_NEAR(P.site_reference_radius, healthy(s_true), 1e-3);
  EXPECT_NEAR(P.percent_diameter_stenosis(), expected_pct, 0.1);
  // The same rule as the segmentation ROI: the shared function on the raw
  // radius gives the same site.
  const StenosisProfile prof = analyse_stenoses(cl.abscissa, cl.radius);
  ASSERT_NE(prof.most_severe(), nullptr);
  EXPECT_NEAR(prof.most_severe()->abscissa, P.site_abscissa, 0.5 * kSample);
  EXPECT_NEAR(prof.most_severe()->percent_diameter(), 30.0, 0.1);

  // summary.yaml and placement.yaml carry the same site and percent stenosis.
  const fs::path dir = temp_dir("taper");
  write_vtp((dir / "centerline.vtp").string(), centerline_mesh(straight, length, radius));
  Summary sp;
  run_placement_stage(prm, dir / "centerline.vtp", std::nullopt, BalloonDesign{}, StentDesign{}, dir / "placement.yaml",
                      dir / "balloon_centerline.vtp", sp);
  EXPECT_DOUBLE_EQ(std::get<double>(sp.qois().at("stenosis_abscissa").value), P.site_abscissa);
  EXPECT_DOUBLE_EQ(std::get<double>(sp.qois().at("stenosis_percent_diameter").value), P.percent_diameter_stenosis());
  EXPECT_DOUBLE_EQ(std::get<double>(sp.qois().at("reference_lumen_diameter").value), 2 * P.site_reference_radius);
  const Placement Q = read_placement_yaml(dir / "placement.yaml");
  EXPECT_DOUBLE_EQ(Q.site_abscissa, P.site_abscissa);
  EXPECT_DOUBLE_EQ(Q.percent_diameter_stenosis(), P.percent_diameter_stenosis());
  fs::remove_all(dir);
}
