// `stentsim solve SCENE.yaml`: the finite-element solve of a scene file, on
// its own (the solve stage of a case calls the same function).
#include "solver/app/solve.hpp"
#include "workflows/cli/commands.hpp"

namespace stentsim::cli {

void register_solve(CLI::App& app) {
  struct Args {
    std::string scene, out, linear, restart;
    int checkpoint_every = -1;
    int threads = 0;
    bool verbose = false;
  };
  auto a = std::make_shared<Args>();
  auto* sub = app.add_subcommand("solve", "Solve a scene file (bodies, materials, loads, solver settings)");
  sub->add_option("scene", a->scene, "Scene file (YAML)")->required();
  sub->add_option("--out", a->out, "Output folder (default: beside the scene file)");
  sub->add_option("--linear-solver", a->linear, "Override the scene's linear solver")
      ->check(CLI::IsMember(solver::linear_solver_names()));
  sub->add_flag("--verbose,-v", a->verbose, "Log every Newton iteration");
  auto* restart = sub->add_option("--restart", a->restart,
                                  "Resume from a checkpoint (output.checkpoint_every); default: OUT/checkpoint.bin")
                      ->expected(0, 1);
  sub->add_option("--checkpoint-every", a->checkpoint_every, "Write checkpoint.bin every N steps (overrides output.checkpoint_every)")
      ->check(CLI::Range(0, 1000000));
  sub->add_option("--threads", a->threads,
                  "Threads of the element loops per rank (default: $STENTSIM_THREADS, else the cores over the ranks)")
      ->check(CLI::Range(1, 1024));
  on(sub, [a, restart] {
    solver::SolveOptions o;
    o.output_dir = a->out;
    if (!a->linear.empty()) o.linear_solver = solver::parse_linear_solver(a->linear, "--linear-solver");
    o.verbose = a->verbose;
    if (restart->count() > 0) o.restart = std::filesystem::path(a->restart);
    if (a->checkpoint_every >= 0) o.checkpoint_every = a->checkpoint_every;
    if (a->threads > 0) o.threads = a->threads;
    // solve_scene returns non-zero when the computation could not finish
    // (last converged state written); the CLI's code for that is 1.
    return solver::solve_scene(a->scene, o) == 0 ? 0 : 1;
  });
}

}  // namespace stentsim::cli
