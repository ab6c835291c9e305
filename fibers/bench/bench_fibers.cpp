// Benchmark of the harmonic-lifting fiber stage (not a test): a tagged tet10
// tube of about the size of the paper's Case 2 wall (238,123 nodes), the two
// Laplace solves and the frame construction, median of several runs per
// linear solver, wall and CPU time (the machine is shared: CPU time is the
// steadier figure). Usage: bench_fibers [runs=3] [elements_around=96] [elements_along=63] [solvers=gmres_amg]
// or, on a meshed patient wall: bench_fibers artery.vtu centerline.vtp [runs=3] [solvers=gmres_amg]
// (solvers: comma-separated solver/linalg types; "direct" KLU2 takes minutes at
// this size). BENCH_FIBERS_MODES=default,corners,quadratic (comma-separated)
// picks the tet10 discretizations: default (t quadratic, l on the corner
// nodes), corners (both on the corner nodes), quadratic (both quadratic).
#include <algorithm>
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "common/mesh_tags.hpp"
#include "fibers/harmonic_fibers.hpp"
#include "fibers/tagged_tube.hpp"

using namespace stentsim;

namespace {
/// CPU seconds of this process (user + system): on the shared machine the
/// wall time depends on the load, the CPU time much less.
double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}
}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const bool files = argc > 2 && std::string(argv[1]).size() > 4 && std::string(argv[1]).substr(std::string(argv[1]).size() - 4) == ".vtu";
  const int shift = files ? 1 : 0;  // patient mode: runs is argument 3 (not 1)
  const int runs = argc > 1 + 2 * shift ? std::atoi(argv[1 + 2 * shift]) : 3;
  fibers::TaggedTubeSpec s;
  s.inner_radius = 0.95, s.outer_radius = 1.55, s.length = 21.0;  // Case 2: 21 mm segment
  s.elements_radial = 4;
  s.elements_around = argc > 2 ? std::atoi(argv[2]) : 96;
  s.elements_along = argc > 3 ? std::atoi(argv[3]) : 63;
  s.quadratic = true;
  const MeshData mesh = files ? read_vtu(argv[1]) : fibers::tagged_tube(s);
  const MeshData axis = files ? read_vtp(argv[2]) : fibers::tagged_tube_axis(s);
  std::size_t cells = 0, linear = 0;
  for (auto t : mesh.cell_types) cells += t == CellType::quadratic_tetra, linear += t == CellType::tetra;
  std::printf("%s: %zu nodes, %zu tet10, %zu tet4\n", files ? argv[1] : "tet10 tube", mesh.points.size(), cells, linear);
  fibers::HarmonicFiberOptions o;
  o.angles = {{tags::intima, 0.0}, {tags::media, 0.0}, {tags::adventitia, 40.0 * M_PI / 180}};
  std::vector<std::string> solvers;
  {
    std::string list = argc > 4 ? argv[4] : "gmres_amg";
    for (std::size_t p = 0; p != std::string::npos;) {
      const std::size_t q = list.find(',', p);
      solvers.push_back(list.substr(p, q == std::string::npos ? q : q - p));
      p = q == std::string::npos ? q : q + 1;
    }
  }
  std::vector<std::string> modes;
  {
    const char* m = std::getenv("BENCH_FIBERS_MODES");
    std::string list = m ? m : "default";
    for (std::size_t p = 0; p != std::string::npos;) {
      const std::size_t q = list.find(',', p);
      modes.push_back(list.substr(p, q == std::string::npos ? q : q - p));
      p = q == std::string::npos ? q : q + 1;
    }
  }
  for (const auto& mode : modes)
  for (const auto& name : solvers) {
    o.linear_on_corners = mode != "quadratic";
    o.transmural_on_corners = mode == "corners";
    std::printf("mode %s\n", mode.c_str());
    const char* solver = name.c_str();
    o.linear_solver = solver::parse_linear_solver(solver, "bench_fibers: solver list");
    std::vector<double> total, laplace, cpu;
    for (int r = 0; r < runs; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = cpu_seconds();
      const auto res = fibers::harmonic_fibers(mesh, axis, o);
      total.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      laplace.push_back(res.laplace_seconds);
      cpu.push_back(cpu_seconds() - c0);
      if (r == 0)
        std::printf("%s: unknowns %zu + %zu, iterations %d + %d, residual %.2e/%.2e, neighbour fiber angle max %.2f deg, "
                    "t in [%.3g, %.3g], l in [%.3g, %.3g]\n", solver, res.transmural_unknowns, res.longitudinal_unknowns,
                    res.transmural_iterations, res.longitudinal_iterations, res.transmural_residual, res.longitudinal_residual,
                    res.quality.max_neighbour_fiber_angle_deg, res.quality.transmural_min, res.quality.transmural_max,
                    res.quality.longitudinal_min, res.quality.longitudinal_max);
    }
    std::sort(total.begin(), total.end());
    std::sort(laplace.begin(), laplace.end());
    std::sort(cpu.begin(), cpu.end());
    std::printf("%s: median total %.2f s wall, %.2f s CPU (Laplace solves %.2f s wall) over %d runs\n", solver,
                total[total.size() / 2], cpu[cpu.size() / 2], laplace[laplace.size() / 2], runs);
  }
  return 0;
}
