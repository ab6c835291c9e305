// Benchmark (not a test, issue 8): residual + tangent of the 210-element
// 4-ring stent per Newton iteration on one core, (a) elements only (the
// assembler receives the element blocks and discards them) and (b) through
// the solver core's Model + GlobalSystem (CSR assembly). Median of 7 runs.
// Wall and CPU time (getrusage). Build and run:
//   ninja -C <build> bench_solver_beams && <build>/tests/solver/bench_solver_beams [repeats, default 50]
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

#include <sys/resource.h>

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
  // Wall time and CPU time (user + system of this process, getrusage): on a shared, loaded machine the
  // CPU time is the robust number (the benchmark is single-threaded).
  auto cpu_ms = [] {
    rusage r{};
    getrusage(RUSAGE_SELF, &r);
    return 1e3 * (r.ru_utime.tv_sec + r.ru_stime.tv_sec) + 1e-3 * (r.ru_utime.tv_usec + r.ru_stime.tv_usec);
  };
  struct Timing {
    double wall_ms, cpu_ms;
  };
  auto median_ms = [&](const auto& once) {
    once();  // warm-up (and the CSR pattern)
    std::vector<double> wall, cpu;
    for (int k = 0; k < 7; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = cpu_ms();
      for (int r = 0; r < repeats; ++r) once();
      cpu.push_back((cpu_ms() - c0) / repeats);
      wall.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / repeats);
    }
    std::sort(wall.begin(), wall.end());
    std::sort(cpu.begin(), cpu.end());
    return Timing{wall[3], cpu[3]};
  };
  const Timing t = median_ms([&] { beam.assemble(state, sink); });
  std::printf("stent beams: %zu elements, %lld DOFs, %d Gauss points per element: residual + tangent %.3f ms wall, "
              "%.3f ms CPU per iteration (%.2f us CPU per element), elements only, median of 7 [checksum %.3e]\n",
              s.body.elements.size(), static_cast<long long>(n), static_cast<int>(beam.reference(0).points.size()),
              t.wall_ms, t.cpu_ms, 1000.0 * t.cpu_ms / s.body.elements.size(), sink.checksum);

  Model m;
  const GlobalDof first = m.dofs.allocate("stent", n);
  m.size_constraints();
  m.add_term<BeamTerm>("stent", s.body, number_beam_dofs(s.body, first, &n));
  for (std::size_t k = 0; k < s.body.nodes.size(); ++k)
    static_cast<BeamTerm&>(*m.terms[0]).set_rotation(static_cast<int>(k), beam.rotation(static_cast<int>(k)));
  GlobalSystem system(m.constraints);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  const Timing tg = median_ms([&] { m.assemble(u, 1.0, 0.1, zero, system, true); });
  std::printf("stent beams through Model + GlobalSystem (CSR, %lld nonzeros): %.3f ms wall, %.3f ms CPU per "
              "iteration, median of 7\n",
              static_cast<long long>(system.matrix().values.size()), tg.wall_ms, tg.cpu_ms);
  return 0;
}
