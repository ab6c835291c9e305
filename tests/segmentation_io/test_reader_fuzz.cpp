// Mutation fuzzing of the surface readers, in process: mutated copies of valid
// files (bit flips, byte insertions and deletions, truncation, a huge count, NaN
// text, an index past the points) must each either read or fail with an
// InputError; a crash, a hang or any other exception fails the test. A fixed
// seed and 300 inputs per format here (quick; 5,000 under the validation label); STENTSIM_FUZZ_ITERATIONS
// runs more. A mutant that reads is a valid input: garbage results are the
// targeted tests' to catch (test_surface_input.cpp).
#include <gtest/gtest.h>
#include <vtkPolyDataWriter.h>

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>

#include "common/error.hpp"
#include "common/mesh_data.hpp"
#include "segmentation_io/phantom.hpp"
#include "segmentation_io/surface_input.hpp"
#include "tests/fuzz/mutation.hpp"
#include "tests/segmentation_io/polydata_fixture.hpp"

using namespace stentsim;
using namespace stentsim::segmentation;
namespace fs = std::filesystem;

namespace {

TriSurface small_tube() {
  PhantomSpec s = phantom_preset("straight-healthy", 1);
  s.length = 4;
  s.circumferential_points = 12;
  return surface_from_mesh(build_phantom(s).lumen, "tube");
}

std::string ascii_stl(const TriSurface& s) {
  std::string o = "solid t\n";
  for (const auto& t : s.triangles) {
    o += "facet normal 0 0 1\n outer loop\n";
    for (int v : t)
      o += "  vertex " + std::to_string(s.points[v].x()) + " " + std::to_string(s.points[v].y()) + " " +
           std::to_string(s.points[v].z()) + "\n";
    o += " endloop\nendfacet\n";
  }
  return o + "endsolid t\n";
}

std::string binary_stl(const TriSurface& s) {
  std::string o(80, ' ');
  const auto n = static_cast<std::uint32_t>(s.triangles.size());
  o.append(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : s.triangles) {
    float v[12] = {};
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) v[3 + 3 * k + c] = static_cast<float>(s.points[t[k]][c]);
    o.append(reinterpret_cast<const char*>(v), sizeof v);
    o.append(2, '\0');
  }
  return o;
}

std::string obj(const TriSurface& s) {
  std::string o;
  for (const auto& p : s.points) o += "v " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
  for (const auto& t : s.triangles) o += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
  return o;
}

std::string legacy_vtk(const TriSurface& s) {
  std::string o = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS " + std::to_string(s.points.size()) + " double\n";
  for (const auto& p : s.points) o += std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
  o += "POLYGONS " + std::to_string(s.triangles.size()) + " " + std::to_string(4 * s.triangles.size()) + "\n";
  for (const auto& t : s.triangles) o += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  return o;
}

// Legacy VTK as VTK 9.1's writer makes it (5.1: OFFSETS/CONNECTIVITY).
std::string vtk51_text(const fs::path& dir, const TriSurface& s) {
  auto w = vtkSmartPointer<vtkPolyDataWriter>::New();
  w->SetInputData(to_polydata(s));
  w->SetFileName((dir / "seed51.vtk").c_str());
  w->Write();
  std::ifstream in(dir / "seed51.vtk", std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// ... and in its binary form (big-endian arrays after each keyword line): mutants
// reach the counts and the raw offsets and connectivity.
std::string vtk51_binary(const fs::path& dir, const TriSurface& s) {
  auto w = vtkSmartPointer<vtkPolyDataWriter>::New();
  w->SetInputData(to_polydata(s));
  w->SetFileTypeToBinary();
  w->SetFileName((dir / "seed51b.vtk").c_str());
  w->Write();
  std::ifstream in(dir / "seed51b.vtk", std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string vtp_text(const fs::path& dir, const TriSurface& s) {
  write_vtp((dir / "seed.vtp").string(), mesh_from_surface(s));
  std::ifstream in(dir / "seed.vtp", std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST(ReaderFuzz, MutatedSurfacesReadOrFailWithAnInputError) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_reader_fuzz_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const TriSurface tube = small_tube();
  // VTK 9.1's XML reader crashes (SIGSEGV) on some .vtp mutants inside its own parser:
  // read_surface_file reads such a file in a child process first (check_vtk_xml_file).
  std::map<std::string, std::string> seeds = {{"ascii.stl", ascii_stl(tube)}, {"binary.stl", binary_stl(tube)},
                                              {"t.obj", obj(tube)}, {"t.vtk", legacy_vtk(tube)},
                                              {"t51.vtk", vtk51_text(dir, tube)}, {"t51b.vtk", vtk51_binary(dir, tube)},
                                              {"t.vtp", vtp_text(dir, tube)}};
  std::mt19937 gen(20261202);
  const int n = fuzz::iterations();
  for (const auto& [name, seed] : seeds) {
    int read = 0, refused = 0;
    for (int i = 0; i < n; ++i) {
      const std::string input = fuzz::mutate(seed, gen);
      const fs::path f = dir / name;
      {
        std::ofstream out(f, std::ios::binary | std::ios::trunc);
        out << input;
      }
      try {
        const TriSurface s = read_surface_file(f);
        for (const auto& t : s.triangles)
          for (int v : t) ASSERT_TRUE(v >= 0 && static_cast<std::size_t>(v) < s.points.size()) << name << " mutant " << i;
        for (const auto& p : s.points) ASSERT_TRUE(p.allFinite()) << name << " mutant " << i;
        ++read;
      } catch (const InputError& e) {
        ++refused;
        ASSERT_NE(std::string(e.what()).find(f.string()), std::string::npos) << name << " mutant " << i << ": " << e.what();
      } catch (const std::exception& e) {
        FAIL() << name << " mutant " << i << ": not an InputError: " << e.what();
      }
    }
    std::printf("%-11s %d mutants: %d read, %d refused with an input error\n", name.c_str(), n, read, refused);
    std::fflush(stdout);
  }
  fs::remove_all(dir);
}
