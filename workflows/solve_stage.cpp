#include "workflows/solve_stage.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_tags.hpp"
#include "pipeline/child_process.hpp"
#include "solver/app/solve.hpp"
#include "solver/io/scene.hpp"
#include "solver/linalg/linear_solver.hpp"

namespace stentsim::workflows {
namespace fs = std::filesystem;
namespace {

std::string free_expansion_scene(const CaseConfig& c, const std::string& balloon, const std::string& stent) {
  const SimulationSettings& s = c.simulation;
  const double T = s.phase_duration, dt = T / s.load_steps;
  std::ostringstream y;
  y << fmt::format(
      "# Written by the solve stage of the case {case} (scene {scene}). Re-run by hand:\n"
      "#   stentsim solve scene.yaml --out DIR\n"
      "# Free expansion (paper 3.1, DESIGN.md §3, §5): balloon + stent, stent–balloon beam-to-surface\n"
      "# contact, balloon ends on Robin springs, the stent's fixation nodes; inflation to p_max over\n"
      "# one phase, deflation over the next (\"max\" = t {T:g}, \"after\" = t {T2:g}).\n"
      "description: free expansion of '{name}', p_max {p:g} MPa\n\n",
      fmt::arg("case", c.file.string()), fmt::arg("scene", to_string(c.scene)), fmt::arg("T", T),
      fmt::arg("T2", 2 * T), fmt::arg("name", c.name), fmt::arg("p", s.pressure_max));
  y << fmt::format(
      "bodies:\n"
      "  - name: balloon\n"
      "    mesh: {{file: {b}}}\n"
      "    materials:\n"
      "      - preset: balloon          # neo-Hooke E 17 MPa, ν 0; longitudinal and circumferential fibers; viscous branch\n"
      "    fiber_frames:                # the straight balloon's axis: frames exact at every Gauss point\n"
      "      cylindrical: {{origin: [0, 0, 0], axis: [0, 0, 1]}}\n"
      "  - name: stent\n"
      "    beam: {{file: {st}, material: stent, joints: rigid}}   # App. C elasto-plastic beams\n\n",
      fmt::arg("b", balloon), fmt::arg("st", stent));
  y << fmt::format("load_curves:\n  inflation: [[0, 0], [{:.17g}, 1], [{:.17g}, 0]]\n\n", T, 2 * T);
  y << fmt::format(
      "conditions:\n"
      "  - name: inflation\n"
      "    type: pressure\n"
      "    body: balloon\n"
      "    surface: {{cell_array: {{name: FaceGroup, value: {inner}}}}}   # inner face\n"
      "    value: {p:.17g} MPa\n"
      "    curve: inflation\n"
      "  - name: balloon_end_proximal\n"
      "    type: springs\n"
      "    body: balloon\n"
      "    surface: {{cell_array: {{name: FaceGroup, value: {prox}}}}}\n"
      "    stiffness: {k:.17g} N/mm^3\n"
      "  - name: balloon_end_distal\n"
      "    type: springs\n"
      "    body: balloon\n"
      "    surface: {{cell_array: {{name: FaceGroup, value: {dist}}}}}\n"
      "    stiffness: {k:.17g} N/mm^3\n"
      "  - name: stent_fixations\n"
      "    type: direction                # radial fixation nodes move only radially, the axial one keeps d·u = 0\n"
      "    body: stent\n"
      "    node: fixations\n"
      "    direction: file\n\n",
      fmt::arg("inner", static_cast<int>(tags::balloon_inner)), fmt::arg("prox", static_cast<int>(tags::balloon_end_proximal)),
      fmt::arg("dist", static_cast<int>(tags::balloon_end_distal)), fmt::arg("p", s.pressure_max),
      fmt::arg("k", s.balloon_end_springs));
  y << fmt::format(
      "contact:\n"
      "  - name: stent_balloon\n"
      "    type: beam_to_surface\n"
      "    beam: stent\n"
      "    solid: balloon\n"
      "    surface: {{cell_array: {{name: FaceGroup, value: {outer}}}}}   # outer face\n"
      "    penalty: {eps:.17g} N/mm^2\n"
      "    times: {{max: {T:.17g}, after: {T2:.17g}}}\n\n",
      fmt::arg("outer", static_cast<int>(tags::balloon_outer)), fmt::arg("eps", s.beam_penalty), fmt::arg("T", T),
      fmt::arg("T2", 2 * T));
  y << fmt::format(
      "solver:\n"
      "  time: {{start: 0, end: {T2:.17g}, dt: {dt:.17g}, dt_max: {dt:.17g}, dt_min: {dtmin:.17g}}}\n"
      "  newton: {{max_iterations: 25, residual_tolerance: 1.0e-8, increment_tolerance: 1.0e-8}}\n"
      "  linear: {{type: {lin}}}\n\n"
      "output:\n  every: {every}\n\n",
      fmt::arg("T2", 2 * T), fmt::arg("dt", dt), fmt::arg("dtmin", dt * 1e-4),
      fmt::arg("lin", solver::linear_solver_name(s.linear_solver)), fmt::arg("every", c.output.every));
  // Balloon profiles at fractions of p_max on the way up (the paper's balloon figure).
  std::string fractions;
  for (double f : {0.2, 0.4, 0.6, 0.8, 1.0}) fractions += fmt::format("{}{:.6g}", fractions.empty() ? "" : ", ", f * s.pressure_max);
  y << fmt::format(
      "qoi:\n"
      "  - name: stent\n"
      "    type: stent_expansion          # ring diameters, recoil, dogboning (DESIGN.md §8), centroid curvature\n"
      "    body: stent\n"
      "    pressure: inflation\n"
      "    times: {{max: {T:.17g}, after: {T2:.17g}}}\n"
      "  - name: balloon\n"
      "    type: balloon_profile          # outer diameter along the (straight) axis\n"
      "    body: balloon\n"
      "    surface: {{cell_array: {{name: FaceGroup, value: {outer}}}}}\n"
      "    axis: {{origin: [0, 0, 0], direction: [0, 0, 1]}}\n"
      "    pressure: inflation\n"
      "    pressures: [{fr}]          # MPa\n"
      "    times: {{max: {T:.17g}, after: {T2:.17g}}}\n",
      fmt::arg("T", T), fmt::arg("T2", 2 * T), fmt::arg("outer", static_cast<int>(tags::balloon_outer)),
      fmt::arg("fr", fractions));
  return y.str();
}

/// The scene text with the artifacts' paths given as `balloon`, `stent`.
std::string scene_text(const CaseConfig& c, const std::string& balloon, const std::string& stent) {
  if (c.scene != Scene::free_expansion)
    throw InputError(fmt::format("{}: scene '{}': this version builds the solve stage for free-expansion scenes only",
                                 c.file.string(), to_string(c.scene)));
  return free_expansion_scene(c, balloon, stent);
}

/// `mpirun` over `ranks` (or $STENTSIM_MPI_LAUNCH, e.g. inside a Slurm task).
std::vector<std::string> mpi_launcher(int ranks) {
  if (const char* l = std::getenv("STENTSIM_MPI_LAUNCH"); l && *l) {
    std::vector<std::string> argv;
    std::istringstream words(l);
    for (std::string w; words >> w;) argv.push_back(w);
    return argv;
  }
  return {"mpirun", "--allow-run-as-root", "--oversubscribe", "-np", std::to_string(ranks)};
}

}  // namespace

bool solve_stage_available(const CaseConfig& c) { return c.scene == Scene::free_expansion; }

std::string solve_scene_text(const CaseConfig& c) {
  return scene_text(c, "../balloon/balloon.vtu", "../stent/stent.vtu");
}

pipeline::Stage solve_stage(const CaseConfig& c) {
  pipeline::Stage s;
  s.name = "solve";
  s.inputs = {"balloon/balloon.vtu", "stent/stent.vtu"};
  s.outputs = {"solve/scene.yaml", "solve/results.pvd", "solve/results/", "solve/history.csv"};
  s.version = "1";
  const std::string text = solve_scene_text(c);  // input errors before anything runs
  // The scene is everything the solve depends on besides its input files.
  s.config = text + fmt::format("ranks={};", c.simulation.ranks);
  const CaseConfig cfg = c;
  s.run = [text, cfg](pipeline::StageContext& ctx) {
    const fs::path scene_out = ctx.output("solve/scene.yaml");
    files::write_atomic(scene_out, text);
    const fs::path out_dir = scene_out.parent_path();
    // Read as the file it becomes (work/solve/scene.yaml), so its relative paths hold.
    const fs::path final_scene = ctx.work_dir() / "solve" / "scene.yaml";
    if (cfg.simulation.ranks <= 1) {
      const solver::SceneDesc scene = solver::read_scene(text, final_scene);
      solver::SolveOptions o;
      o.output_dir = out_dir;
      if (solver::solve(scene, o, ctx.summary()) != 0)
        throw ComputeError(fmt::format("the solve did not finish (the log says where and why); its last converged state, "
                                       "history.csv and summary are kept in {}",
                                       (ctx.work_dir() / "failed" / "solve" / "solve").string()));
      return;
    }
    // MPI: a copy of the scene with absolute paths, run by `stentsim solve` under mpirun.
    const fs::path run_scene = out_dir.parent_path() / "run_scene.yaml";
    files::write_atomic(run_scene, scene_text(cfg, (ctx.work_dir() / "balloon" / "balloon.vtu").string(),
                                            (ctx.work_dir() / "stent" / "stent.vtu").string()));
    std::vector<std::string> argv = mpi_launcher(cfg.simulation.ranks);
    for (const std::string& a : {pipeline::self_executable().string(), std::string("solve"), run_scene.string(),
                                std::string("--out"), out_dir.string()})
      argv.push_back(a);
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = pipeline::spawn_exec(argv);
    const pipeline::ChildEnd end = pipeline::wait_with_limit(pid, start, 1e9);
    if (!end.ok())
      throw ComputeError(fmt::format("the MPI solve ({} ranks) ended with {}; see the log", cfg.simulation.ranks, end.describe()));
    ctx.summary() = Summary::read(out_dir / "summary.yaml");
  };
  return s;
}

}  // namespace stentsim::workflows
