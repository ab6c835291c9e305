// The patient mesh is reproducible: the same input gives the same nodes
// (bitwise), elements and tags, in one process after the heap has changed and
// in another process (content hashes and cohorts rely on it). gmsh 4.8's HXT
// (mesh.algorithm_3d: hxt) fails this: its adapter orders the nodes by address.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <unistd.h>
#include <string>
#include <vector>

#include "meshing/patient_mesh.hpp"
#include "tube_fixtures.hpp"

using namespace stentsim;

namespace {

constexpr const char* kChildEnv = "STENTSIM_TEST_PRINT_MESH_FINGERPRINT";

struct Result {
  std::size_t points = 0, cells = 0;
  std::string fingerprint;
};

Result mesh_bent_tube() {
  meshing::PatientMeshOptions o;
  o.element = "tet10";
  o.size = 0.5;
  if (const char* a = std::getenv("STENTSIM_TEST_MESH_ALGORITHM")) o.algorithm_3d = a;  // to see HXT fail this test
  const test::BentPath p{0.5, 4.0, 0.6, 0.5};  // 3.4 mm, a bend through 34°
  const auto w = meshing::wall_sections(test::path_tube(p, 1.0), test::path_tube(p, 1.5), test::path_centerline(p), o);
  const MeshData m =
      meshing::mesh_wall_sections(w, o, std::filesystem::temp_directory_path() / "stentsim_test_determinism.msh");
  return {m.points.size(), m.num_cells(), meshing::mesh_fingerprint(m)};
}

}  // namespace

TEST(PatientMeshDeterminism, SameInputSameMeshInProcessAndAcrossProcesses) {
  const Result first = mesh_bent_tube();
  if (std::getenv(kChildEnv)) {  // the child run below: report and stop
    std::printf("FINGERPRINT %s %zu %zu\n", first.fingerprint.c_str(), first.points, first.cells);
    return;
  }
  ASSERT_GT(first.cells, 500u);
  // Rearrange the heap: blocks of many sizes, every other one freed, so the
  // second run's objects land at other relative addresses (what changed the
  // HXT meshes between two runs in one process).
  std::vector<std::unique_ptr<char[]>> junk;
  for (int i = 0; i < 20000; ++i) junk.emplace_back(new char[std::size_t(16 + (i * 37) % 200)]);
  for (std::size_t i = 0; i < junk.size(); i += 2) junk[i].reset();
  const Result second = mesh_bent_tube();
  EXPECT_EQ(second.points, first.points);
  EXPECT_EQ(second.cells, first.cells);
  EXPECT_EQ(second.fingerprint, first.fingerprint);

  // Another process (its own address layout): this test binary, this test.
  const std::string cmd = std::string(kChildEnv) + "=1 /proc/" + std::to_string(getpid()) +
                          "/exe --gtest_filter=PatientMeshDeterminism.SameInputSameMeshInProcessAndAcrossProcesses";
  FILE* f = popen(cmd.c_str(), "r");
  ASSERT_NE(f, nullptr);
  char line[512];
  std::string child;
  while (std::fgets(line, sizeof line, f))
    if (std::string(line).rfind("FINGERPRINT ", 0) == 0) child = line;
  ASSERT_EQ(pclose(f), 0);
  char hash[64] = {};
  std::size_t np = 0, nc = 0;
  ASSERT_EQ(std::sscanf(child.c_str(), "FINGERPRINT %63s %zu %zu", hash, &np, &nc), 3) << child;
  EXPECT_EQ(np, first.points);
  EXPECT_EQ(nc, first.cells);
  EXPECT_EQ(std::string(hash), first.fingerprint);
  std::printf("bent tube tet10: %zu points, %zu cells, fingerprint %s in both runs and the child process\n",
              first.points, first.cells, first.fingerprint.c_str());
}
