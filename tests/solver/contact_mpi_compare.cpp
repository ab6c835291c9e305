// Compares two runs of examples/contact_ring_on_balloon.yaml under `mpirun
// -np 1` and `-np 2` (beam elements, hence contact points, split over the
// ranks; every rank searches all of them). Usage: solver_contact_mpi_compare
// DIR_NP1 DIR_NP2. Exit 0 when the ring and contact QoIs agree to 1e-8
// relative: the runs differ by the order of the assembly sums only.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/summary.hpp"

using namespace stentsim;

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s DIR_NP1 DIR_NP2\n", argv[0]);
    return 2;
  }
  const std::filesystem::path a = argv[1], b = argv[2];
  const Summary sa = Summary::read(a / "summary.yaml"), sb = Summary::read(b / "summary.yaml");
  double worst = 0.0;
  for (const char* k : {"D_max", "D_end", "recoil_percent", "max_bending_moment_peak", "contact_force_stent_balloon_max",
                        "contact_line_load_max_stent_balloon_max", "contact_mean_penetration_stent_balloon_max",
                        "contact_active_points_stent_balloon_max", "steps"}) {
    const double x = std::get<double>(sa.qois().at(k).value), y = std::get<double>(sb.qois().at(k).value);
    const double d = std::abs(x - y) / std::max(1e-12, std::abs(x));
    std::printf("%-44s np1 %.12g  np2 %.12g  rel. difference %.2e\n", k, x, y, d);
    worst = std::max(worst, d);
  }
  std::printf("contact ring on balloon, np1 vs np2: largest relative difference %.2e\n", worst);
  return worst <= 1e-8 ? 0 : 1;
}
