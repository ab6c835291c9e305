// Smoothing of a kinked centerline with a bounded displacement (sharp bends
// and kinks at lesions and junctions): sections normal to a kink meet inside
// the wall whatever their spacing, so the curve is smoothed, each point kept
// within its bound of the raw path.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "segmentation_io/polyline_frames.hpp"

using namespace stentsim::segmentation;
using Eigen::Vector3d;

namespace {

/// Smallest radius of curvature over chords of m samples either side (the
/// mesh's sections are 0.5 mm apart with tangents over 0.5 mm: m = 5).
double min_bend_radius(const std::vector<Vector3d>& p, std::size_t m = 5) {
  double r = 1e300;
  for (std::size_t i = m; i + m < p.size(); ++i) {
    const Vector3d a = (p[i] - p[i - m]).normalized(), b = (p[i + m] - p[i]).normalized();
    const double turn = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
    if (turn > 1e-12) r = std::min(r, 0.5 * ((p[i] - p[i - m]).norm() + (p[i + m] - p[i]).norm()) / turn);
  }
  return r;
}

}  // namespace

// Two straight 5 mm legs meeting at 45° (every 0.1 mm): over the mesh's
// 0.5 mm chords the raw corner bends with radius 0.64 mm; smoothed (length
// 1 mm, bound 0.3 mm) nearly twice that, no point moves beyond its bound,
// the ends stay and the legs away from the corner stay put.
TEST(CenterlineSmoothing, KinkIsRoundedWithinTheBound) {
  std::vector<Vector3d> p;
  const double a = std::numbers::pi / 4;
  for (int i = 0; i <= 50; ++i) p.emplace_back(0, 0, 0.1 * i);
  for (int i = 1; i <= 50; ++i) p.emplace_back(0.1 * i * std::sin(a), 0, 5 + 0.1 * i * std::cos(a));
  const std::vector<Vector3d> raw = p;
  const double before = min_bend_radius(p);
  const std::vector<double> bound(p.size(), 0.3);
  const double moved = smooth_with_bounded_displacement(p, bound, 10.0);
  const double after = min_bend_radius(p);
  std::printf("bend radius at the kink %.3f mm -> %.3f mm, largest move %.4f mm (bound 0.3)\n", before, after, moved);
  EXPECT_LT(before, 0.65);
  EXPECT_GT(after, 1.1);
  EXPECT_LE(moved, 0.3 + 1e-12);
  EXPECT_GT(moved, 0.05);
  EXPECT_EQ(p.front(), raw.front());
  EXPECT_EQ(p.back(), raw.back());
  // Away from the kink (3 mm along either leg) the points stay put.
  EXPECT_LT((p[20] - raw[20]).norm(), 1e-3);
  EXPECT_LT((p[80] - raw[80]).norm(), 1e-3);
}

// A smooth arc (R = 5 mm, the tortuous phantom's) keeps its shape: as many
// plain Laplacian steps would pull it in by about h² n / (4R) = 0.4 mm.
TEST(CenterlineSmoothing, SmoothArcBarelyMoves) {
  std::vector<Vector3d> p;
  for (int i = 0; i <= 200; ++i) {
    const double t = 0.02 * i;  // 0.1 mm steps on R = 5
    p.emplace_back(5 * std::sin(t), 0, 5 * (1 - std::cos(t)));
  }
  const std::vector<double> bound(p.size(), 0.3);
  const double moved = smooth_with_bounded_displacement(p, bound, 10.0);
  std::printf("arc R = 5 mm: largest move %.5f mm\n", moved);
  EXPECT_LT(moved, 0.01);
}
