// Compares two runs of examples/stent_ring_expansion.yaml (issue 9): under
// `mpirun -np 1` and `-np 2` (the beam elements split over the ranks, every
// rank holding the whole plastic history; the radial multipliers and release
// forces added on rank 0). Usage: solver_ring_mpi_compare DIR_NP1 DIR_NP2.
// Exit 0 when the ring QoIs and the last frame's beam arrays agree to 1e-9
// (the two runs differ by round-off in the assembly order only).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "common/mesh_data.hpp"
#include "common/summary.hpp"

using namespace stentsim;

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s DIR_NP1 DIR_NP2\n", argv[0]);
    return 2;
  }
  const std::filesystem::path a = argv[1], b = argv[2];
  const Summary sa = Summary::read(a / "summary.yaml"), sb = Summary::read(b / "summary.yaml");
  double dq = 0.0;
  for (const char* k : {"D_max", "D_end", "recoil_percent", "max_bending_moment_peak", "max_bending_moment_end",
                        "plastic_work_end", "stored_energy_end", "external_work", "steps"}) {
    const double x = std::get<double>(sa.qois().at(k).value), y = std::get<double>(sb.qois().at(k).value);
    std::printf("%-26s np1 %.12g  np2 %.12g\n", k, x, y);
    dq = std::max(dq, std::abs(x - y) / std::max(1.0, std::abs(x)));
  }
  const std::string last = "results/ring_00030.vtu";
  const MeshData ma = read_vtu((a / last).string()), mb = read_vtu((b / last).string());
  double du = 0.0;
  for (const char* arr : {"Displacement", "BendingMoment", "PlasticCurvature", "AccumulatedPlasticCurvature", "Yielding"}) {
    const auto& x = ma.point_data.at(arr).values;
    const auto& y = mb.point_data.at(arr).values;
    if (x.size() != y.size()) {
      std::printf("%s: sizes differ\n", arr);
      return 1;
    }
    for (std::size_t i = 0; i < x.size(); ++i) du = std::max(du, std::abs(x[i] - y[i]));
  }
  std::printf("ring np1 vs np2: max relative QoI difference %.2e, max last-frame array difference %.2e\n", dq, du);
  return dq <= 1e-9 && du <= 1e-9 ? 0 : 1;
}
