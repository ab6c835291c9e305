// `stentsim mesh` on the tortuous phantom (bends and a 40 % stenosis):
// passes the pre-loft section checks and meshes at a coarse size with valid
// elements (validation: about a minute of CPU).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "common/mesh_data.hpp"
#include "common/mesh_tags.hpp"
#include "meshing/patient_mesh.hpp"
#include "tests/workflows/cli_runner.hpp"

namespace fs = std::filesystem;
using stentsim::testing::run_stentsim;

TEST(PatientMeshCli, TortuousPhantomMeshesAtCoarseSize) {
  const fs::path dir = fs::temp_directory_path() / "stentsim_test_mesh_tortuous";
  const auto r = stentsim::testing::mesh_phantom("tortuous", dir, "--element tet4 --size 0.6");
  ASSERT_EQ(r.code, 0) << r.out;
  const YAML::Node s = YAML::LoadFile((dir / "mesh/summary.yaml").string());
  const double gap = s["qoi"]["min_section_gap_ratio"]["value"].as<double>();
  EXPECT_GE(gap, 0.1);
  EXPECT_LE(gap, 1.0 + 1e-9);
  const auto m = stentsim::read_vtu((dir / "mesh/artery.vtu").string());
  const auto q = stentsim::meshing::mesh_quality(m);
  for (int L : {stentsim::tags::intima, stentsim::tags::media, stentsim::tags::adventitia})
    EXPECT_GT(q.elements_per_layer[std::size_t(L)], 1000u);
  EXPECT_GT(q.min_scaled_jacobian, 0.05);
  std::printf("tortuous tet4 at 0.6 mm: %zu points, smallest section gap %.3f of the spacing, min scaled Jacobian %.3f, "
              "max aspect ratio %.2f, fingerprint %s\n",
              m.points.size(), gap, q.min_scaled_jacobian, q.max_aspect_ratio,
              s["notes"]["mesh_fingerprint"].as<std::string>().c_str());
  fs::remove_all(dir);
}
