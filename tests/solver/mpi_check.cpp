// Run under mpirun -np 2: the same problem solved serially on each rank
// (Eigen LU, all elements) and in parallel (elements split over the ranks,
// direct (gathered on rank 0), GMRES + Schwarz-ILU(k) and GMRES + SA-AMG over the ranks) must agree to solver
// tolerance. A media tube (fibers + viscous history) under inner pressure.
#include <limits>
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "common/log.hpp"
#include <numbers>

#include "solver/assembly/parallel.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/materials/presets.hpp"
#include "solver/nonlinear/load_stepper.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "solver/terms/robin_springs.hpp"

using namespace stentsim;
using namespace stentsim::solver;

namespace {

Eigen::VectorXd solve(int rank, int ranks, const std::string& linear_type) {
  MeshData mesh = ring_sector_hex8(0.8, 1.4, std::numbers::pi / 2, 0.3, 3, 8, 2);
  Model model;
  model.rank = rank;
  model.ranks = ranks;
  SolidBodySpec spec;
  spec.name = "tube";
  spec.mesh = mesh;
  spec.materials = {material_preset("media")};
  spec.cell_material.assign(mesh.num_cells(), 0);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    Vec3 x = Vec3::Zero();
    for (auto n : mesh.cell(c)) x += mesh.points[static_cast<std::size_t>(n)];
    const Vec3 er = Vec3(x.x(), x.y(), 0).normalized();
    spec.cell_frames.push_back({er, Vec3::UnitZ().cross(er), Vec3::UnitZ()});
  }
  auto& body = model.add_term<SolidBody>(spec, model.dofs.allocate("tube", 3 * static_cast<GlobalDof>(mesh.points.size())));
  std::vector<fem::Face> inner, ends;
  for (const auto& f : fem::boundary_faces(body.mesh())) {
    bool in = true, end = true;
    for (int i = 0; i < f.count; ++i) {
      const Vec3& p = body.mesh().points[static_cast<std::size_t>(f.nodes[i])];
      in = in && p.head<2>().norm() < 0.8 + 1e-9;
      end = end && (p.z() < 1e-9 || p.z() > 0.3 - 1e-9);
    }
    if (in) inner.push_back(f);
    if (end) ends.push_back(f);
  }
  model.add_term<FollowerPressure>("p", body, inner, 0.012, LoadCurve::ramp(0, 1));
  model.add_term<RobinSprings>("ends", body, ends, 1.0);
  model.size_constraints();
  for (std::size_t i = 0; i < body.num_nodes(); ++i) {
    const Vec3 p = body.mesh().points[i];
    if (std::abs(p.y()) < 1e-12) model.constraints.fix(body.dof(i, 1), [](double) { return 0.0; });
    if (std::abs(p.x()) < 1e-12) model.constraints.fix(body.dof(i, 0), [](double) { return 0.0; });
  }
  GlobalSystem sys(model.constraints);
  LinearSolverSettings ls;
  ls.type = parse_linear_solver(linear_type, "mpi check");
  ls.tolerance = 1e-12;
  auto linear = make_linear_solver(ls);
  if (linear_type == "gmres_amg") {
    std::vector<std::pair<GlobalDof, Vec3>> nodes;
    for (std::size_t i = 0; i < body.num_nodes(); ++i) nodes.emplace_back(body.dof(i, 0), body.mesh().points[i]);
    linear->set_near_null_space(model.rigid_body_modes(nodes));
  }
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
  StepperSettings st;
  st.dt_initial = 0.25;
  st.dt_max = 0.25;
  NewtonSettings ns;
  ns.residual_tolerance = 1e-11;
  bool timings_ok = true;
  run_load_steps(model, sys, *linear, u, st, ns, [&](const StepRecord& r) {
    // The linear set-up time is a part of the linear time (the gathered direct
    // solve once counted its factorization twice: negative solve times).
    timings_ok = timings_ok && r.linear_setup_seconds >= 0 && r.linear_setup_seconds <= r.linear_seconds + 1e-6;
  });
  if (!timings_ok) {
    std::printf("%s: linear set-up time outside [0, linear time]\n", linear_type.c_str());
    u.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  return u;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int status = 0;
  {
    const int rank = parallel::rank(), ranks = parallel::size();
    if (std::getenv("STENTSIM_DEBUG")) log::set_level(log::Level::debug);
    const Eigen::VectorXd serial = solve(0, 1, "eigen_lu");
    for (const char* type : {"direct", "gmres_ilu", "gmres_amg"}) {
      const Eigen::VectorXd par = solve(rank, ranks, type);
      const double diff = (par - serial).norm() / serial.norm();
      if (rank == 0) std::printf("%d ranks, %s vs serial: relative difference %.2e (|u| = %.4e)\n", ranks, type, diff, serial.norm());
      if (!(diff < 1e-8)) status = 1;
    }
    if (ranks < 2 && rank == 0) std::printf("note: run under mpirun -np 2 to exercise the partition\n");
  }
  MPI_Finalize();
  return status;
}
