// Solver benchmark (issue 6, "Performance"; not a test): the paper's Case 1
// artery alone (structured hex8 two-layer HGO tube, 11 mm long, outer
// diameter 2.8 mm, wall 0.6 mm, ~27,000 DOFs, springs on the cut faces),
// 85 mmHg prestress then inner pressure to 0.2 MPa. Reports time per Newton
// iteration split into assembly and linear solve for the chosen solver, and
// the assembly of 130,000 tet10 elements with the HGO material (scatter included) on 1
// and 2 threads.
//   bench_solver [direct|gmres_ilu|gmres_amg|eigen_lu] [--tet10 | --prestress-only | --coarse | --mesh=NR,NT,NZ]
// --prestress-only stops after the 85 mmHg phase (one step): enough for the
// per-iteration timings. The exponential fibers stiffen the wall, so the
// artery alone has an equilibrium at 0.2 MPa at a modest stretch: plane-strain
// radial BVP with this energy (tests/solver/hgo_tube_reference.hpp) gives
// inner radius 1.245 mm (hoop stretch 1.556); --coarse (3x16x8 hex8, direct)
// reaches 0.2 MPa with mid inner radius 1.2449 mm, max fiber stretch 1.47
// (media) / 1.20 (adventitia). The step just past 85 mmHg is the hard one
// (the tangent there is still soft, the first Newton iterate overshoots and
// inverts elements: the stepper cuts it). With gmres_amg the GMRES solves
// stall (2000 iterations, 1e-4..1e-6) once the fibers are stretched.
// --coarse / --mesh print the state after every step. Run under mpirun -np 2 for two ranks.
#include <mpi.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <vector>
#include <numbers>

#include "common/log.hpp"
#include "common/units.hpp"
#include "solver/assembly/global_system.hpp"
#include "solver/assembly/parallel.hpp"
#include "solver/assembly/threads.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/materials/presets.hpp"
#include "solver/nonlinear/load_stepper.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "solver/terms/robin_springs.hpp"

using namespace stentsim;
using namespace stentsim::solver;
using Clock = std::chrono::steady_clock;

namespace {

std::array<Vec3, 3> cylindrical_frame(const MeshData& m, std::size_t c) {
  Vec3 x = Vec3::Zero();
  const auto conn = m.cell(c);
  for (auto n : conn) x += m.points[static_cast<std::size_t>(n)];
  const Vec3 er = Vec3(x.x(), x.y(), 0).normalized();
  return {er, Vec3::UnitZ().cross(er), Vec3::UnitZ()};
}

double cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// Discards contributions (measures element evaluation alone).
class NullAssembler : public Assembler {
 public:
  void add(std::span<const GlobalDof>, const Eigen::Ref<const Eigen::VectorXd>& r, const Eigen::Ref<const Eigen::MatrixXd>& k) override {
    sink += r(0) + (k.size() ? k(0, 0) : 0.0);
  }
  double sink = 0.0;
};

// The assembly figure: 130k tet10 HGO (26 x 26 x 32 hex8, 6 tets each), residual
// and tangent scattered into the global matrix (its pattern laid by a first assembly),
// on 1 and 2 threads; medians of 5. The element evaluation alone (no scatter) beside it.
void tet10_throughput() {
  MeshData mesh = tet4_to_tet10(hex8_to_tet4(box_hex8(26, 26, 32, 2.6, 2.6, 3.2)));  // 129,792 tet10
  SolidBodySpec spec;
  spec.name = "block";
  spec.mesh = std::move(mesh);
  spec.materials = {material_preset("adventitia")};
  spec.materials[0].fibers[0].global_direction = Vec3(0, 1, 1).normalized();
  spec.materials[0].fibers[1].global_direction = Vec3(0, 1, -1).normalized();
  spec.cell_material.assign(spec.mesh.num_cells(), 0);
  SolidBody body(std::move(spec), 0);
  Eigen::VectorXd u = Eigen::VectorXd::Random(body.num_dofs()) * 1e-3;
  const SystemState state{u, 1.0, 0.1};
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  NullAssembler none;
  const auto t0 = Clock::now();
  body.assemble(state, none);
  const double eval = std::chrono::duration<double>(Clock::now() - t0).count();
  std::printf("tet10 HGO: %zu elements, residual + tangent evaluation alone %.3f s (%.2f us/element), 1 thread\n",
              body.num_elements(), eval, 1e6 * eval / static_cast<double>(body.num_elements()));
  const Constraints constraints(body.num_dofs());
  GlobalSystem system(constraints);
  const Eigen::VectorXd prescribed = Eigen::VectorXd::Zero(body.num_dofs());
  auto assemble = [&] {
    const auto t = Clock::now();
    system.begin(prescribed, true);
    body.assemble(state, system);
    system.finish();
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  const double first = assemble();  // lays the pattern (serial)
  std::printf("  first assembly (lays the matrix pattern, %lld entries): %.3f s\n", static_cast<long long>(system.matrix().nonzeros()), first);
  for (const int threads : {1, 2}) {
    const AssemblyThreads scope(threads);
    std::vector<double> t;
    for (int k = 0; k < 5; ++k) t.push_back(assemble());
    std::printf("  assembly with scatter, %d thread(s): median %.3f s of 5 (min %.3f, max %.3f)\n", threads, median(t),
                *std::min_element(t.begin(), t.end()), *std::max_element(t.begin(), t.end()));
  }
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  const std::string type = argc > 1 ? argv[1] : "direct";
  auto flag = [&](const char* f) {
    for (int i = 2; i < argc; ++i)
      if (std::strcmp(argv[i], f) == 0) return true;
    return false;
  };
  if (flag("--tet10")) {
    if (parallel::rank() == 0) tet10_throughput();
    MPI_Finalize();
    return 0;
  }
  {
    // 6 radial (media 2 x 0.1 mm, adventitia 4 x 0.1 mm: 0.2 / 0.4 mm instead
    // of 0.22 / 0.38 for a uniform structured mesh), 48 around, 26 along.
    const double ri = 0.8, ro = 1.4, length = 11.0;
    // --coarse: 3 radial (media 1, adventitia 2), 16 around, 8 along;
    // --mesh=NR,NT,NZ any other resolution (NR a multiple of 3). Both print the
    // state after every step (diagnosis).
    int nr = 6, nt = 48, nz = 26;
    bool coarse = flag("--coarse");
    if (coarse) nr = 3, nt = 16, nz = 8;
    for (int i = 2; i < argc; ++i)
      if (std::strncmp(argv[i], "--mesh=", 7) == 0 && std::sscanf(argv[i] + 7, "%d,%d,%d", &nr, &nt, &nz) == 3) coarse = true;
    MeshData mesh = ring_sector_hex8(ri, ro, 2 * std::numbers::pi, length, nr, nt, nz);
    SolidBodySpec spec;
    spec.name = "artery";
    spec.materials = {material_preset("media"), material_preset("adventitia")};
    for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
      Vec3 x = Vec3::Zero();
      for (auto n : mesh.cell(c)) x += mesh.points[static_cast<std::size_t>(n)];
      x /= 8.0;
      spec.cell_material.push_back(x.head<2>().norm() < ri + 0.2 ? 0 : 1);
      spec.cell_frames.push_back(cylindrical_frame(mesh, c));
    }
    spec.mesh = std::move(mesh);
    Model model;
    auto& body = model.add_term<SolidBody>(spec, model.dofs.allocate("artery", 3 * static_cast<GlobalDof>(spec.mesh.points.size())));
    std::vector<fem::Face> inner, cuts;
    for (const auto& f : fem::boundary_faces(body.mesh())) {
      bool in = true, cut = true;
      for (int i = 0; i < f.count; ++i) {
        const Vec3& p = body.mesh().points[static_cast<std::size_t>(f.nodes[i])];
        in = in && p.head<2>().norm() < ri + 1e-9;
        cut = cut && (p.z() < 1e-9 || p.z() > length - 1e-9);
      }
      if (in) inner.push_back(f);
      if (cut) cuts.push_back(f);
    }
    const double p_d = 85 * units::kMmHgInMPa;
    // phase 1: 85 mmHg over [0,1]; phase 2: to 0.2 MPa over [1,2]
    const LoadCurve p_curve({{0, 0}, {1, p_d}, {2, 0.2}});
    model.add_term<FollowerPressure>("lumen", body, inner, 1.0, p_curve);
    model.add_term<RobinSprings>("cuts", body, cuts, 1000.0);
    model.size_constraints();
    LinearSolverSettings ls;
    ls.type = parse_linear_solver(type, "bench_solver: first argument");
    ls.tolerance = 1e-8;
    auto linear = make_linear_solver(ls);
    model.rank = parallel::rank();
    model.ranks = parallel::size();
    if (model.rank != 0) log::set_level(log::Level::warn);
    std::vector<std::pair<GlobalDof, Vec3>> nodes;
    for (std::size_t i = 0; i < body.num_nodes(); ++i) nodes.emplace_back(body.dof(i, 0), body.mesh().points[i]);
    linear->set_near_null_space(model.rigid_body_modes(nodes));
    GlobalSystem sys(model.constraints);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
    StepperSettings st;
    const bool prestress_only = flag("--prestress-only");
    st.t_end = prestress_only ? 1.0 : 2.0;
    st.dt_initial = prestress_only ? 1.0 : 0.5;
    st.dt_max = st.dt_initial;
    st.stops = {1.0};
    double assembly = 0, solve = 0, setup = 0;
    int iterations = 0, linear_its = 0;
    const double cpu0 = cpu_seconds();
    const auto t0 = Clock::now();
    // Mid-length inner radius, and the largest fiber stretch sqrt(I4) per layer
    // (I4 = 1 + 2 a.E.a with the cell-mean Green-Lagrange strain).
    // (inner nodes on the node plane nearest mid-length: an odd NZ has none at L/2).
    double z_mid = 0;
    for (const auto& x : body.mesh().points)
      if (std::abs(x.z() - length / 2) < std::abs(z_mid - length / 2)) z_mid = x.z();
    auto mid_inner_radius = [&] {
      double r_sum = 0;
      int n = 0;
      for (std::size_t i = 0; i < body.num_nodes(); ++i)
        if (body.mesh().points[i].head<2>().norm() < ri + 1e-9 && std::abs(body.mesh().points[i].z() - z_mid) < 1e-9)
          r_sum += body.position(u, i).head<2>().norm(), ++n;
      return r_sum / n;
    };
    auto report_state = [&](double time) {
      const auto fields = body.cell_fields(u);
      double max_i4[2] = {0, 0};
      for (std::size_t c = 0; c < body.num_elements(); ++c) {
        const int m = body.cell_material()[c];
        for (int f = 0; f < 2; ++f) {
          const Vec3& a = body.fiber_directions(c)[f];
          max_i4[m] = std::max(max_i4[m], 1.0 + 2.0 * a.dot(fields.strain[c] * a));
        }
      }
      if (model.rank == 0)
        std::printf("  t = %.4f p = %.4f MPa: mid inner radius %.4f mm, max fiber stretch media %.4f, adventitia %.4f\n", time,
                    p_curve(time), mid_inner_radius(), std::sqrt(max_i4[0]), std::sqrt(max_i4[1]));
    };
    try {
      run_load_steps(model, sys, *linear, u, st, {}, [&](const StepRecord& r) {
        assembly += r.assembly_seconds;
        solve += r.linear_seconds;
        setup += r.linear_setup_seconds;
        iterations += r.newton_iterations;
        linear_its += r.linear_iterations;
        if (coarse) report_state(r.time);
      });
    } catch (const LoadStepStall& e) {
      if (model.rank == 0) std::printf("stalled at p = %.4f MPa: %s\n", p_curve(e.time), e.what());
      report_state(e.time);
    }
    const double total = std::chrono::duration<double>(Clock::now() - t0).count();
    const double r_in_mid = mid_inner_radius();
    if (model.rank == 0)
      std::printf("case1 artery: %lld DOFs, %d rank(s), %s: %d Newton its, %d linear its; per Newton iteration: "
                  "assembly %.3f s, linear solve %.3f s (set-up %.3f s, Krylov/solve %.3f s); total %.1f s wall, %.1f s CPU "
                  "(rank 0); mid inner radius at the end %.4f mm\n",
                  static_cast<long long>(model.dofs.size()), model.ranks, linear->describe().c_str(), iterations, linear_its,
                  assembly / iterations, solve / iterations, setup / iterations, (solve - setup) / iterations, total,
                  cpu_seconds() - cpu0, r_in_mid);
  }
  MPI_Finalize();
  return 0;
}
