// Benchmark of the harmonic-lifting fiber stage (not a test): a tagged tet10
// tube of about the size of the paper's Case 2 wall (238,123 nodes), the two
// Laplace solves and the frame construction, median of several runs per
// linear solver. Usage: bench_fibers [runs=3] [elements_around=96] [elements_along=63] [solvers=gmres_ilu]
// or, on a meshed patient wall: bench_fibers artery.vtu centerline.vtp [runs=3] [solvers=gmres_ilu]
// (solvers: comma-separated solver/linalg types; "direct" KLU2 takes minutes at
// this size; on the full quadratic problem of the case2-rca tet10 wall gmres_ilu
// did not finish in 8 minutes: the fibers now solve on the corner nodes).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "common/mesh_tags.hpp"
#include "fibers/harmonic_fibers.hpp"
#include "fibers/tagged_tube.hpp"

using namespace stentsim;

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
    std::string list = argc > 4 ? argv[4] : "gmres_ilu";
    for (std::size_t p = 0; p != std::string::npos;) {
      const std::size_t q = list.find(',', p);
      solvers.push_back(list.substr(p, q == std::string::npos ? q : q - p));
      p = q == std::string::npos ? q : q + 1;
    }
  }
  for (const auto& name : solvers) {
    const char* solver = name.c_str();
    o.linear_solver = solver;
    std::vector<double> total, laplace;
    for (int r = 0; r < runs; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      const auto res = fibers::harmonic_fibers(mesh, axis, o);
      total.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      laplace.push_back(res.laplace_seconds);
      if (r == 0)
        std::printf("%s: iterations %d + %d, residual %.2e/%.2e, neighbour fiber angle max %.2f deg\n", solver,
                    res.transmural_iterations, res.longitudinal_iterations, res.transmural_residual,
                    res.longitudinal_residual, res.quality.max_neighbour_fiber_angle_deg);
    }
    std::sort(total.begin(), total.end());
    std::sort(laplace.begin(), laplace.end());
    std::printf("%s: median total %.2f s (Laplace solves %.2f s) over %d runs\n", solver, total[total.size() / 2],
                laplace[laplace.size() / 2], runs);
  }
  return 0;
}
