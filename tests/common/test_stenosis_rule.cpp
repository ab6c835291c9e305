// The one stenosis rule (common/stenosis_site): lesions against a reference
// line that follows the healthy taper, the ends left out by one reference
// diameter, recovery on both sides, close narrowings merged.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/stenosis_site.hpp"
#include "common/summary.hpp"

using namespace stentsim;

namespace {

struct Profile {
  std::vector<double> S, R;
};

/// Samples every 0.1 mm of r(s) over [0, length].
template <class F>
Profile sample(double length, F r) {
  Profile p;
  for (int i = 0; i * 0.1 <= length + 1e-9; ++i) p.S.push_back(0.1 * i), p.R.push_back(r(0.1 * i));
  return p;
}

/// Cosine dip of `depth` (fraction of the diameter), `width` mm long, at c.
double dip(double s, double c, double depth, double width) {
  const double d = std::abs(s - c);
  return d < 0.5 * width ? depth * 0.5 * (1 + std::cos(2 * std::numbers::pi * d / width)) : 0.0;
}

}  // namespace

// A vessel tapering from r = 1.5 to 1.0 mm over 30 mm, a 40 % lesion at
// 12 mm and a tip that narrows to 0.5 mm over its last 1.5 mm (a tapering
// tip, not a lesion: its own radius would shrink an end exclusion of "one
// end radius" to 1 mm and let it in). Raw narrowest: the tip.
TEST(StenosisRule, TaperedVesselWithTipTaper) {
  auto healthy = [](double s) { return 1.5 - s / 60.0; };
  const Profile p = sample(30.0, [&](double s) {
    const double tip = s > 28.5 ? (s - 28.5) / 1.5 * 0.5 : 0.0;  // down to half the healthy radius at 30 mm
    return healthy(s) * (1 - dip(s, 12.0, 0.40, 6.0)) * (1 - tip);
  });
  const StenosisProfile a = analyse_stenoses(p.S, p.R);
  std::printf("analysed %.2f..%.2f mm, slope %.5f (true %.5f), %zu lesion(s)\n", a.lo, a.hi, a.slope, -1 / 60.0,
              a.lesions.size());
  // Ends: one reference diameter, 3.0 mm at the inlet and 2.0 mm at the outlet.
  EXPECT_NEAR(a.lo, 3.0, 0.02);
  EXPECT_NEAR(a.hi, 28.0, 0.02);
  EXPECT_NEAR(a.slope, -1 / 60.0, 1e-3);
  ASSERT_EQ(a.lesions.size(), 1u);
  const Lesion& l = a.lesions[0];
  std::printf("lesion at %.2f mm, %.2f %% diameter, %.2f %% area, extent %.2f..%.2f mm\n", l.abscissa,
              l.percent_diameter(), l.percent_area(), l.start, l.end);
  EXPECT_NEAR(l.abscissa, 12.0, 0.051);
  EXPECT_NEAR(l.percent_diameter(), 40.0, 1.0);
  EXPECT_NEAR(l.percent_area(), 64.0, 1.5);  // 1 - 0.6²
  EXPECT_NEAR(l.reference_radius, healthy(12.0), 0.01);
  EXPECT_GT(l.start, 9.0);
  EXPECT_LT(l.end, 15.0);
  // The end rule keeps the tip out: the narrowest point of the analysed
  // range is the lesion (an exclusion of one end radius, 0.5 mm, would have
  // reached into the tip, where r / r_ref falls to 0.5).
  EXPECT_NEAR(a.narrowest.abscissa, 12.0, 0.051);
  EXPECT_EQ(a.most_severe(), &a.lesions[0]);
}

// Two 30 % narrowings 2 mm apart with full recovery between them are one
// lesion (merge distance 3 mm), named by the deeper; 8 mm apart they are two.
TEST(StenosisRule, CloseNarrowingsMergeFarOnesDoNot) {
  for (double gap : {2.0, 8.0}) {
    SCOPED_TRACE(gap);
    const double c1 = 10.0, c2 = 10.0 + gap;
    const Profile p = sample(30.0, [&](double s) { return 1.25 * (1 - dip(s, c1, 0.30, 1.6) - dip(s, c2, 0.35, 1.6)); });
    const StenosisProfile a = analyse_stenoses(p.S, p.R);
    for (const Lesion& l : a.lesions)
      std::printf("gap %.0f: lesion at %.2f mm, %.2f %%, %.2f..%.2f mm\n", gap, l.abscissa, l.percent_diameter(), l.start, l.end);
    if (gap < 3.0) {
      ASSERT_EQ(a.lesions.size(), 1u);
      EXPECT_NEAR(a.lesions[0].abscissa, c2, 0.051);  // the deeper names it
      EXPECT_NEAR(a.lesions[0].percent_diameter(), 35.0, 1.0);
      EXPECT_LT(a.lesions[0].start, c1);
      EXPECT_GT(a.lesions[0].end, c2);
    } else {
      ASSERT_EQ(a.lesions.size(), 2u);
      EXPECT_NEAR(a.lesions[0].abscissa, c1, 0.051);
      EXPECT_NEAR(a.lesions[1].abscissa, c2, 0.051);
      EXPECT_EQ(a.most_severe(), &a.lesions[1]);
      EXPECT_EQ(a.nearest(c1 + 0.2), &a.lesions[0]);
    }
  }
}

// Below the threshold, or without recovery on one side, there is no lesion,
// and the message says what was looked for; the threshold is a setting.
TEST(StenosisRule, NoLesionSaysSoAndTheThresholdIsASetting) {
  const Profile shallow = sample(20.0, [](double s) { return 1.0 * (1 - dip(s, 10.0, 0.10, 4.0)); });
  const StenosisProfile a = analyse_stenoses(shallow.S, shallow.R);
  EXPECT_TRUE(a.lesions.empty());
  EXPECT_EQ(a.most_severe(), nullptr);
  const std::string msg = a.no_lesion_message();
  EXPECT_NE(msg.find("stenosis.threshold_percent"), std::string::npos) << msg;
  EXPECT_NE(msg.find("at s = 10.00 mm"), std::string::npos) << msg;  // where the narrowest point is
  auto cfg = ConfigMap::from_string("threshold_percent: 8\nmerge_distance: 1 mm\n", "case.yaml");
  const StenosisRule rule = parse_stenosis_rule(cfg);
  EXPECT_DOUBLE_EQ(rule.merge_distance, 1.0);
  ASSERT_EQ(analyse_stenoses(shallow.S, shallow.R, rule).lesions.size(), 1u);
  // A narrowing that runs into the excluded outlet end does not recover: not a lesion.
  const Profile cut = sample(20.0, [](double s) { return s > 14.0 ? 1.0 - 0.05 * (s - 14.0) : 1.0; });
  EXPECT_TRUE(analyse_stenoses(cut.S, cut.R).lesions.empty());
  // Unknown keys and bad values are errors naming the key.
  auto bad = ConfigMap::from_string("threshold_percent: 120\n", "case.yaml");
  try {
    parse_stenosis_rule(bad);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("threshold_percent"), std::string::npos) << e.what();
  }
  // Shorter than its two excluded ends: analysed whole, and the summary says so.
  const Profile tiny = sample(3.0, [](double) { return 1.0; });
  const StenosisProfile t = analyse_stenoses(tiny.S, tiny.R);
  EXPECT_FALSE(t.ends_excluded);
  EXPECT_DOUBLE_EQ(t.hi - t.lo, 3.0);
  EXPECT_TRUE(analyse_stenoses(shallow.S, shallow.R).ends_excluded);
  // The "cut" narrowing above is deep enough to be one, were it not for the missing recovery.
  EXPECT_GT(analyse_stenoses(cut.S, cut.R).narrowest.percent_diameter(), 15.0);
}

// Every lesion goes to summary.yaml with its measures.
TEST(StenosisRule, LesionsAreListedInTheSummary) {
  const Profile p = sample(30.0, [](double s) { return 1.0 * (1 - dip(s, 8.0, 0.5, 3.0) - dip(s, 20.0, 0.25, 3.0)); });
  StenosisProfile a = analyse_stenoses(p.S, p.R);
  ASSERT_EQ(a.lesions.size(), 2u);
  a.lesions[0].point = std::array<double, 3>{1, 2, 3};
  Summary s;
  report_lesions(a, s);
  EXPECT_DOUBLE_EQ(std::get<double>(s.qois().at("lesion_count").value), 2.0);
  EXPECT_NEAR(std::get<double>(s.qois().at("lesion_1_percent_diameter").value), 50.0, 1.0);
  EXPECT_NEAR(std::get<double>(s.qois().at("lesion_1_percent_area").value), 75.0, 1.5);
  EXPECT_NEAR(std::get<double>(s.qois().at("lesion_2_abscissa").value), 20.0, 0.051);
  EXPECT_EQ(s.qois().count("lesion_1_point"), 1u);
  EXPECT_EQ(s.qois().count("lesion_2_point"), 0u);
  for (const char* k : {"lesion_2_min_radius", "lesion_2_reference_radius", "lesion_2_start", "lesion_2_end"})
    EXPECT_EQ(s.qois().count(k), 1u) << k;
}

// A whole tree path: 100 mm whose radius steps down from 2.0 to 1.2 mm at a
// branch (over 4 mm at s = 40) with a 40 % lesion at 75 mm. One straight
// line over the path would read the distal half as one 50 mm lesion; the
// reference fitted over 20 mm about each point follows the step.
TEST(StenosisRule, ReferenceFollowsATaperStepAlongATreePath) {
  auto healthy = [](double s) { return 1.2 + 0.8 / (1 + std::exp((s - 40.0) / 1.0)); };
  const Profile p = sample(100.0, [&](double s) { return healthy(s) * (1 - dip(s, 75.0, 0.40, 6.0)); });
  const StenosisProfile a = analyse_stenoses(p.S, p.R);
  for (const Lesion& l : a.lesions)
    std::printf("tree path: lesion at %.2f mm, %.2f %%, %.2f..%.2f mm\n", l.abscissa, l.percent_diameter(), l.start, l.end);
  ASSERT_EQ(a.lesions.size(), 1u);
  EXPECT_NEAR(a.lesions[0].abscissa, 75.0, 0.051);
  EXPECT_NEAR(a.lesions[0].percent_diameter(), 40.0, 1.5);
  EXPECT_NEAR(a.reference_at(75.0), 1.2, 0.02);
  EXPECT_NEAR(a.reference_at(20.0), 2.0, 0.02);
  // The same path against one straight line (a window longer than the path):
  // the step reads as lesions, the symptom the window removes.
  StenosisRule straight;
  straight.reference_window = 1000.0;
  const StenosisProfile b = analyse_stenoses(p.S, p.R, straight);
  ASSERT_FALSE(b.lesions.empty());
  EXPECT_GT(b.lesions.back().end - b.lesions.back().start, 15.0);
}
