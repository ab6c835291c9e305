// Benchmark (not a test, issue 8): residual + tangent of the 210-element
// 4-ring stent per Newton iteration on one core, (a) elements only (the
// assembler receives the element blocks and discards them) and (b) through
// the solver core's Model + GlobalSystem (CSR assembly). Median of 7 runs.
// Build: cmake --build <dir> --target bench_solver_beams; run the binary.
#include "solver/assembly/model.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/rotation.hpp"
#include "solver/beams/stent_body.hpp"

#include "device_gen/device_axis.hpp"
#include "device_gen/stent_design.hpp"
#include "device_gen/stent_mesh.hpp"
#include "device_gen/stent_model.hpp"

#include <algorithm>
#include <chrono>
#include <vector>
#include <cstdio>
#include <random>

using namespace stentsim;
using namespace stentsim::solver;
using namespace stentsim::solver::beams;

namespace {
struct SinkAssembler : Assembler {
  double checksum = 0.0;
  void add(std::span<const GlobalDof>, const Eigen::Ref<const Eigen::VectorXd>& r,
           const Eigen::Ref<const Eigen::MatrixXd>& k) override {
    checksum += r[0] + k(0, 0);
  }
};
}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::atoi(argv[1]) : 50;
  device_gen::StentDesign d;
  const device_gen::StentModel model = device_gen::build_stent(d, device_gen::DeviceAxis::straight(9.4));
  const StentBeams s = stent_beams_from_mesh(device_gen::stent_to_mesh(model, d), 380000.0, 190000.0, "stent");
  GlobalDof n = 0;
  BeamTerm beam("stent", s.body, number_beam_dofs(s.body, 0, &n));
  // A deformed state: small random displacements and rotations.
  std::mt19937 g(1);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  Eigen::VectorXd u(n);
  for (long i = 0; i < n; ++i) u[i] = 0.01 * uni(g);
  for (std::size_t k = 0; k < s.body.nodes.size(); ++k)
    beam.set_rotation(static_cast<int>(k),
                      quat_exp(0.2 * Eigen::Vector3d(uni(g), uni(g), uni(g))) * s.body.nodes[k].triad);
  SinkAssembler sink;
  SystemState state{u, 1.0, 0.1};
  auto median_ms = [&](const auto& once) {
    once();  // warm-up (and the CSR pattern)
    std::vector<double> runs;
    for (int k = 0; k < 7; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      for (int r = 0; r < repeats; ++r) once();
      runs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / repeats);
    }
    std::sort(runs.begin(), runs.end());
    return runs[3];
  };
  const double ms = median_ms([&] { beam.assemble(state, sink); });
  std::printf("stent beams: %zu elements, %lld DOFs, %d Gauss points per element: residual + tangent %.3f ms per "
              "iteration (%.2f us per element), elements only, median of 7 [checksum %.3e]\n",
              s.body.elements.size(), static_cast<long long>(n), static_cast<int>(beam.reference(0).points.size()), ms,
              1000.0 * ms / s.body.elements.size(), sink.checksum);

  Model m;
  const GlobalDof first = m.dofs.allocate("stent", n);
  m.size_constraints();
  m.add_term<BeamTerm>("stent", s.body, number_beam_dofs(s.body, first, &n));
  for (std::size_t k = 0; k < s.body.nodes.size(); ++k)
    static_cast<BeamTerm&>(*m.terms[0]).set_rotation(static_cast<int>(k), beam.rotation(static_cast<int>(k)));
  GlobalSystem system(m.constraints);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  const double ms_global = median_ms([&] { m.assemble(u, 1.0, 0.1, zero, system, true); });
  std::printf("stent beams through Model + GlobalSystem (CSR, %lld nonzeros): %.3f ms per iteration, median of 7\n",
              static_cast<long long>(system.matrix().values.size()), ms_global);
  return 0;
}
