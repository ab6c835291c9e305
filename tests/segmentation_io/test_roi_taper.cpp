// The region of interest around the stenosis of a tapering vessel (issue 3):
// a lumen narrowing distally from r = 2.0 to 0.8 mm over 20 mm with a 30 %
// diameter stenosis at 6 mm. The raw narrowest radius is the healthy distal
// end (0.86 mm at 19 mm < 1.148 mm at the stenosis); the taper-discounted
// site is the stenosis.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "common/error.hpp"
#include "segmentation_io/centerline.hpp"
#include "segmentation_io/tree_input.hpp"
#include "tests/segmentation_io/radial_tube.hpp"

using namespace stentsim;
using namespace stentsim::segmentation;
using Eigen::Vector3d;

namespace {

const double kLength = 20.0;
double healthy(double s) { return 2.0 - 0.06 * s; }
// Cosine dip of 30 % in diameter, 4 mm long, centred at 6 mm.
double lumen_radius(double s) {
  const double d = std::abs(s - 6.0);
  const double dip = d < 2.0 ? 0.30 * 0.5 * (1 + std::cos(M_PI * d / 2.0)) : 0.0;
  return healthy(s) * (1 - dip);
}

TriSurface tapered_tube(int rings, int around) {
  return stentsim::testing::radial_tube(kLength, [](double z, double) { return lumen_radius(z); }, rings, around);
}

CenterlineResult straight_centerline(int n) {
  CenterlineResult cl;
  DataArray S{1, {}}, R{1, {}};
  std::vector<std::int64_t> ids;
  for (int i = 0; i <= n; ++i) {
    const double s = kLength * i / n;
    cl.centerline.points.emplace_back(0, 0, s);
    S.values.push_back(s);
    R.values.push_back(lumen_radius(s));
    ids.push_back(i);
  }
  cl.centerline.add_cell(CellType::polyline, ids);
  cl.centerline.point_data["Abscissas"] = S;
  cl.centerline.point_data["MaximumInscribedSphereRadius"] = R;
  cl.length = kLength;
  // What the centerline stage reports as the narrowest site: the distal end region.
  cl.stenosis_abscissa = kLength - 1.0;
  cl.stenosis_point = Vector3d(0, 0, kLength - 1.0);
  return cl;
}

}  // namespace

TEST(RoiTaper, SiteDiscountsTheTaper) {
  const auto cl = straight_centerline(200);
  const auto& S = cl.centerline.point_data.at("Abscissas").values;
  const auto& R = cl.centerline.point_data.at("MaximumInscribedSphereRadius").values;
  // The raw minimum between the same bounds is at the distal bound.
  std::size_t imin = 0;
  for (std::size_t i = 0; i < S.size(); ++i)
    if (S[i] >= 1.0 && S[i] <= 19.0 && R[i] < R[imin]) imin = i;
  EXPECT_NEAR(S[imin], 19.0, 1e-9);
  const StenosisProfile prof = analyse_stenoses(S, R);
  ASSERT_EQ(prof.lesions.size(), 1u);
  const Lesion& t = prof.lesions[0];
  std::printf("lesion %.3f mm (true 6), r %.4f, r_ref %.4f (true %.4f), slope %.4f (true -0.06), %.2f %% (true 30)\n",
              t.abscissa, t.radius, t.reference_radius, healthy(6.0), t.slope, t.percent_diameter());
  EXPECT_NEAR(t.abscissa, 6.0, 0.11);
  EXPECT_NEAR(t.slope, -0.06, 0.003);
  EXPECT_NEAR(t.reference_radius, healthy(6.0), 0.02 * healthy(6.0));
  EXPECT_NEAR(t.percent_diameter(), 30.0, 1.5);
  // Without taper the same rule finds the same site as the raw minimum.
  std::vector<double> flat(R.size());
  for (std::size_t i = 0; i < S.size(); ++i) flat[i] = R[i] / healthy(S[i]) * 1.5;
  ASSERT_NE(analyse_stenoses(S, flat).most_severe(), nullptr);
  EXPECT_NEAR(analyse_stenoses(S, flat).most_severe()->abscissa, 6.0, 0.11);
  EXPECT_THROW(analyse_stenoses({0.0, 1.0}, {1.0, 1.0}), ComputeError);
}

TEST(RoiTaper, RegionOfInterestIsCentredOnTheStenosisNotTheDistalEnd) {
  const auto cl = straight_centerline(200);
  const TriSurface lumen = tapered_tube(400, 48);
  double s0 = 0, s1 = 0;
  TaperedStenosis site;
  const TriSurface roi = clip_region_of_interest(lumen, cl, 8.0, StenosisRule{}, std::nullopt, s0, s1, &site);
  std::printf("ROI %.3f .. %.3f mm around %.3f mm\n", s0, s1, site.abscissa);
  EXPECT_NEAR(0.5 * (s0 + s1), 6.0, 0.11);
  EXPECT_NEAR(s1 - s0, 8.0, 1e-9);
  double zmin = 1e300, zmax = -1e300;
  for (const auto& p : roi.points) zmin = std::min(zmin, p.z()), zmax = std::max(zmax, p.z());
  EXPECT_NEAR(zmin, s0, 1e-6);
  EXPECT_NEAR(zmax, s1, 1e-6);
}

namespace {

// The centerline stage reports the same taper-discounted stenosis (issue 3:
// the narrowest site, % diameter against the reference): on the tapering tube
// the raw minimum is the distal end, the reported site the 30 % dip at 6 mm.
TEST(CenterlineStenosis, TaperingTubeReportsTheDipNotTheDistalEnd) {
  CenterlineResult r = compute_centerline(tapered_tube(200, 64), CenterlineOptions{});
  // The polygonal section's inscribed radius is cos(pi/64) of the vertex radius.
  const double c = std::cos(M_PI / 64);
  std::printf("site %.3f mm (true 6), radius %.4f (true %.4f), reference %.4f (true %.4f), taper %.4f (true -0.06), "
              "%%DS %.2f (true 30)\n",
              r.stenosis_abscissa, r.min_radius, c * lumen_radius(6.0), r.reference_radius, c * healthy(6.0),
              r.reference_taper, r.stenosis_percent_diameter);
  EXPECT_NEAR(r.stenosis_abscissa, 6.0, 0.5);
  EXPECT_NEAR(r.min_radius, c * lumen_radius(6.0), 0.03 * lumen_radius(6.0));
  EXPECT_NEAR(r.reference_radius, c * healthy(6.0), 0.03 * healthy(6.0));
  EXPECT_NEAR(r.reference_taper, -0.06, 0.01);
  EXPECT_NEAR(r.stenosis_percent_diameter, 30.0, 2.0);
}

}  // namespace
