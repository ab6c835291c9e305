// Benchmark (not a test) of the contact terms: bench_contact.sh. The stent and
// balloon files are the device stages'; the wall is a generated tet10 tube
// (inner radius 0.70 mm, 350°, 18 mm). Every pair is evaluated at a state
// that puts all of its points in contact (the balloon pushed out by 0.22 mm,
// the stent by 0.08 mm): beam points at 7,056, the balloon's 2,765 outer faces
// on the wall. Per Newton iteration the solver assembles once with the tangent
// and at least once without (line search): both are timed (medians of 5),
// with the search of begin_step, next to one UMFPACK solve of the whole system.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/log.hpp"
#include "solver/app/built_model.hpp"
#include "solver/assembly/global_system.hpp"
#include "solver/contact/beam_to_surface_pair.hpp"
#include "solver/contact/surface_to_surface_pair.hpp"
#include "solver/io/scene.hpp"
#include "solver/linalg/linear_solver.hpp"

using namespace stentsim;
using namespace stentsim::solver;
using Clock = std::chrono::steady_clock;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <class F>
double time_median(int repeats, F&& f) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = Clock::now();
    f();
    t.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
  }
  return median(t);
}

}  // namespace

int main(int argc, char** argv) {
  const bool contact_only = argc == 4 && std::string(argv[3]) == "--contact-only";  // no direct solve (for profiling)
  if (argc != 3 && !contact_only) {
    std::fprintf(stderr, "usage: %s STENT.vtu BALLOON.vtu [--contact-only] (see bench_contact.sh)\n", argv[0]);
    return 2;
  }
  log::set_level(log::Level::warn);
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("stentsim_bench_contact_{}", ::getpid());
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "scene.yaml") << fmt::format(R"(
bodies:
  - name: balloon
    mesh: {{file: {}}}
    materials: [{{preset: balloon}}]
    fiber_frames: {{cylindrical: {{origin: [0, 0, 0], axis: [0, 0, 1]}}}}
  - name: stent
    beam: {{file: {}, material: stent, joints: rigid}}
  - name: wall
    mesh: {{generate: {{type: ring_sector, element: tet10, inner_radius: 0.70, outer_radius: 1.0, angle_deg: 350,
                        height: 18, radial: 1, circumferential: 20, axial: 72}}}}
    materials: [{{preset: media}}]
    fiber_frames: {{cylindrical: {{origin: [0, 0, 0], axis: [0, 0, 1]}}}}
contact:
  - {{name: stent_balloon, type: beam_to_surface, beam: stent, solid: balloon,
     surface: {{cell_array: {{name: FaceGroup, value: 6}}}}, penalty: 10 N/mm^2}}
  - {{name: stent_wall, type: beam_to_surface, beam: stent, solid: wall,
     surface: {{cylinder: {{origin: [0, 0, 0], axis: [0, 0, 1], radius: 0.70, tolerance: 0.01}}}}, penalty: 10 N/mm^2}}
  - {{name: balloon_wall, type: surface_to_surface, slave: {{body: balloon, surface: {{cell_array: {{name: FaceGroup, value: 6}}}}}},
     master: {{body: wall, surface: {{cylinder: {{origin: [0, 0, 0], axis: [0, 0, 1], radius: 0.70, tolerance: 0.01}}}}}},
     penalty: 5 N/mm^3, search_margin: 0.3 mm}}
solver: {{time: {{end: 1}}, newton: {{}}, linear: {{type: direct}}}}
output: {{}}
)",
                                                 std::filesystem::absolute(argv[2]).string(), std::filesystem::absolute(argv[1]).string());
  const SceneDesc scene = read_scene(dir / "scene.yaml");
  auto built = build_model(scene);
  Model& model = built->model;
  // The state: balloon pushed out radially by 0.22 mm, the stent by 0.08 mm (the wall stays).
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
  const SolidBody& balloon = built->solid("balloon");
  for (std::size_t n = 0; n < balloon.num_nodes(); ++n) {
    const Vec3& x = balloon.mesh().points[n];
    const Vec3 er = Vec3(x.x(), x.y(), 0).normalized();
    for (int c = 0; c < 3; ++c) u[balloon.dof(n, c)] = 0.22 * er[c];
  }
  const beams::BeamTerm& stent = built->beam("stent");
  for (std::size_t n = 0; n < stent.dofs().size(); ++n) {
    const auto& d = stent.dofs()[n];
    if (d.pos[0] < 0) continue;
    const Vec3 x = stent.body().nodes[n].position;
    const Vec3 er = Vec3(x.x(), x.y(), 0).normalized();
    for (int c = 0; c < 3; ++c) u[d.pos[static_cast<std::size_t>(c)]] = 0.08 * er[c];
  }
  const SystemState state{u, 1.0, 1.0};
  GlobalSystem system(model.constraints);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.dofs.size());
  std::printf("model: %lld DOFs; stent %zu elements, balloon %zu cells, wall %zu cells\n", static_cast<long long>(model.dofs.size()),
              stent.body().elements.size(), balloon.num_elements(), built->solid("wall").num_elements());
  double contact_total = 0.0;
  for (auto& t : model.terms) {
    auto* beam_pair = dynamic_cast<contact::BeamToSurfacePair*>(t.get());
    auto* surface_pair = dynamic_cast<contact::SurfaceToSurfacePair*>(t.get());
    if (!beam_pair && !surface_pair) continue;
    const double search = time_median(5, [&] { t->begin_step(state); });
    auto assemble = [&](bool tangent) {
      system.begin(zero, tangent);
      t->assemble(state, system);
      system.finish();
    };
    const auto before = system.matrix().nonzeros();
    assemble(true);  // the first assembly reserves the pattern
    const auto reserved = system.matrix().nonzeros() - before;
    const double with_tangent = time_median(5, [&] { assemble(true); });
    const double residual = time_median(5, [&] { assemble(false); });
    std::string active;
    if (beam_pair) {
      int n = 0, all = 0;
      for (const auto& p : beam_pair->evaluate(u)) n += p.active, ++all;
      active = fmt::format("{} of {} beam points active", n, all);
    } else {
      int n = 0;
      const auto st = surface_pair->evaluate(u);
      for (const auto& s : st.nodes) n += s.active;
      active = fmt::format("{} of {} slave nodes active, {} slave faces", n, st.nodes.size(), surface_pair->slave().faces().size());
    }
    std::printf("%-14s search %7.1f ms, assembly with tangent %7.1f ms, residual only %7.1f ms (%s; %lld matrix entries)\n",
                t->name().c_str(), 1e3 * search, 1e3 * with_tangent, 1e3 * residual, active.c_str(), static_cast<long long>(reserved));
    contact_total += with_tangent + residual;
  }
  if (contact_only) {
    std::printf("per Newton iteration: contact (tangent + one residual) %.1f ms\n", 1e3 * contact_total);
    std::filesystem::remove_all(dir);
    return 0;
  }
  // One direct solve of the whole assembled system at u, for scale.
  system.begin(zero, true);
  double assembly = time_median(1, [&] { model.assemble(u, 1.0, 1.0, zero, system, true); });
  LinearSolverSettings ls;
  auto linear = make_linear_solver(ls);
  Eigen::VectorXd du;
  const double solve = time_median(1, [&] { linear->solve(system.matrix(), system.rhs(), du); });
  std::printf("per Newton iteration: contact (tangent + one residual) %.1f ms; whole model assembly %.1f ms; direct solve %.1f ms "
              "(UMFPACK, first factorization)\n", 1e3 * contact_total, 1e3 * assembly, 1e3 * solve);
  std::filesystem::remove_all(dir);
  return 0;
}
