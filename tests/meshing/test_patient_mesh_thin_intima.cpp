// Patient wall mesh where the wall is thinner than the media + adventitia
// rule (DESIGN.md §8): the intima keeps mesh.min_intima (0.05 mm by default),
// media and adventitia shrink in proportion, and the thin intima still meshes
// with a quality margin. The tube is straight-healthy's cross-section (lumen
// radius 1.25 mm, wall 0.5 mm: the rule asks 0.75 mm of media + adventitia).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "common/mesh_tags.hpp"
#include "meshing/patient_mesh.hpp"
#include "tube_fixtures.hpp"

using namespace stentsim;

namespace {
constexpr double kRl = 1.25, kRw = 1.75, kLen = 3.0;

meshing::WallSections thin_tube_sections(const meshing::PatientMeshOptions& o) {
  return meshing::wall_sections(test::straight_tube(kRl, kLen), test::straight_tube(kRw, kLen),
                                test::straight_centerline(kLen), o);
}
}  // namespace

TEST(PatientMeshThinIntima, DefaultKeepsTheDesignMinimumIntima) {
  const meshing::PatientMeshOptions o;
  EXPECT_EQ(o.min_intima, 0.05);  // DESIGN.md §8
  const auto w = thin_tube_sections(o);
  ASSERT_EQ(w.layers, (std::vector<int>{tags::intima, tags::media, tags::adventitia}));
  EXPECT_EQ(w.clamped_fraction, 1.0);  // every ray: 0.5 mm wall < 0.75 + 0.05 mm
  for (std::size_t s = 0; s < w.origin.size(); ++s)
    for (std::size_t i = 0; i < w.radius[s][0].size(); ++i) {
      const double ti = w.radius[s][1][i] - w.radius[s][0][i], tm = w.radius[s][2][i] - w.radius[s][1][i],
                   ta = w.radius[s][3][i] - w.radius[s][2][i];
      ASSERT_NEAR(ti, 0.05, 1e-9) << "section " << s << " ray " << i;
      // Media and adventitia share the rest in the ratio of the rule.
      EXPECT_NEAR(tm / ta, o.media_ratio / o.adventitia_ratio, 1e-9);
      EXPECT_NEAR(ti + tm + ta, kRw - kRl, 2e-3);  // faceted surfaces (96 around)
    }
}

// At the default size (0.25 mm) the 0.05 mm intima gets the floor size
// 0.125 mm, 2.5 times its thickness. With the nested lofts sharing their
// seam (before mesh stage version 4) the surface meshes of the interfaces
// lay over one another and flat tets with two nodes on each interface
// remained; the bounds here are twice the default quality bounds' margins.
TEST(PatientMeshThinIntima, ThinIntimaMeshesWithAQualityMargin) {
  meshing::PatientMeshOptions o;
  o.element = "tet4";  // straight-sided tet10 has the same shape measures
  const auto w = thin_tube_sections(o);
  const auto m = meshing::mesh_wall_sections(w, o, std::filesystem::temp_directory_path() / "stentsim_test_thin_intima.msh");
  const auto q = meshing::mesh_quality(m);
  std::printf("thin intima tube (0.05 / %.3f / %.3f mm): %zu intima, %zu media, %zu adventitia tets, min scaled "
              "Jacobian %.3f (%s), max aspect ratio %.2f (%s)\n",
              w.radius[0][2][0] - w.radius[0][1][0], w.radius[0][3][0] - w.radius[0][2][0],
              q.elements_per_layer[tags::intima], q.elements_per_layer[tags::media], q.elements_per_layer[tags::adventitia],
              q.min_scaled_jacobian, tags::layer_name(q.worst_sj_layer), q.max_aspect_ratio,
              tags::layer_name(q.worst_ar_layer));
  for (int L : {tags::intima, tags::media, tags::adventitia}) EXPECT_GT(q.elements_per_layer[std::size_t(L)], 500u);
  EXPECT_GT(q.min_scaled_jacobian, 2 * o.min_scaled_jacobian);
  EXPECT_LT(q.max_aspect_ratio, 0.5 * o.max_aspect_ratio);
}
