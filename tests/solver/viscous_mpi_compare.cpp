// Compares runs of tests/solver/viscous_mpi_restart.yaml (issue 6 review): the
// uninterrupted run on 1 rank (reference), the uninterrupted run on 2 ranks and
// the 2-rank run resumed from the 2-rank run's step-4 checkpoint. Usage:
//   solver_viscous_mpi_compare DIR_NP1 DIR_NP2 DIR_NP2_RESUMED
// Exit 0 when the last frame's displacements and Cauchy stresses (the viscous
// part included: every rank's history is gathered at commit and checkpointed)
// and the QoI agree to 1e-8 relative, and the resumed run did start from the
// checkpoint (wrote frames 5 and 6 only).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "common/mesh_data.hpp"
#include "common/summary.hpp"

using namespace stentsim;
namespace fs = std::filesystem;

namespace {

double relative_difference(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size()) return 1e300;
  double d = 0.0, n = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) d = std::max(d, std::abs(x[i] - y[i])), n = std::max(n, std::abs(x[i]));
  return d / std::max(n, 1e-300);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s DIR_NP1 DIR_NP2 DIR_NP2_RESUMED\n", argv[0]);
    return 2;
  }
  const fs::path ref = argv[1];
  const std::string last = "results/tube_00006.vtu";
  const MeshData m_ref = read_vtu((ref / last).string());
  const double r_ref = std::get<double>(Summary::read(ref / "summary.yaml").qois().at("inner_radius_end").value);
  int status = 0;
  for (int k = 2; k <= 3; ++k) {
    const fs::path dir = argv[k];
    const MeshData m = read_vtu((dir / last).string());
    const double du = relative_difference(m.point_data.at("Displacement").values, m_ref.point_data.at("Displacement").values);
    const double ds = relative_difference(m.cell_data.at("CauchyStress").values, m_ref.cell_data.at("CauchyStress").values);
    const double r = std::get<double>(Summary::read(dir / "summary.yaml").qois().at("inner_radius_end").value);
    const double dr = std::abs(r - r_ref) / r_ref;
    std::printf("%s vs %s: displacement %.2e, Cauchy stress %.2e, inner radius %.2e (relative)\n", dir.string().c_str(),
                ref.string().c_str(), du, ds, dr);
    if (!(du <= 1e-8 && ds <= 1e-8 && dr <= 1e-8)) status = 1;
  }
  // The resumed run started at its checkpoint (step 4): frames 5 and 6 written, frames 1-4 not.
  const fs::path resumed = argv[3];
  for (int f = 1; f <= 6; ++f) {
    const bool has = fs::exists(resumed / ("results/tube_0000" + std::to_string(f) + ".vtu"));
    if (has != (f >= 5)) {
      std::printf("resumed run: frame %d %s: it did not resume from the step-4 checkpoint\n", f, has ? "written" : "missing");
      status = 1;
    }
  }
  return status;
}
