#include "solver/app/solve.hpp"

#include <fmt/format.h>

#include <unistd.h>

#include <chrono>
#include <cmath>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/checkpoint.hpp"
#include "solver/app/run_observer.hpp"
#include "solver/assembly/parallel.hpp"
#include "solver/assembly/threads.hpp"
#include "solver/beams/beam_output.hpp"
#include "solver/io/results_writer.hpp"
#include "solver/io/scene_kinds.hpp"
#include "solver/io/solid_output.hpp"

namespace stentsim::solver {

int solve(const SceneDesc& scene, const SolveOptions& options, Summary& summary) {
  const auto wall_start = std::chrono::steady_clock::now();
  if (options.verbose) log::set_level(log::Level::debug);
  const std::string file = scene.file.string();
  LinearSolverSettings linear_settings = scene.linear;
  if (options.linear_solver) linear_settings.type = *options.linear_solver;
  StepperSettings stepping = scene.stepping;
  const std::filesystem::path out_dir = options.output_dir.empty() ? scene.file.parent_path() : options.output_dir;
  auto built = build_model(scene);
  Model& model = built->model;
  log::info("scene {}: {} DOFs, {} fixed, {} terms", file, model.dofs.size(), model.constraints.num_fixed(), model.terms.size());

  // Observers: the QoIs (checkpoint keys "qoi/<name>/…"), then the contact pairs' outputs ("contact/<pair>/…").
  std::vector<std::pair<std::string, RunObserver*>> observers;
  std::vector<std::unique_ptr<RunObserver>> qois;
  for (const auto& q : scene.qois) {
    qois.push_back(q->observer(scene, *built));
    observers.emplace_back("qoi/" + q->name + "/", qois.back().get());
  }
  for (const auto& o : built->observers) observers.emplace_back(o->checkpoint_name() + "/", o.get());

  auto linear = make_linear_solver(linear_settings);
  if (linear_settings.type == LinearSolverType::gmres_amg) {
    linear->set_near_null_space(amg_near_null_space(scene, *built));
    linear->set_node_coordinates(amg_node_coordinates(*built));
  }
  if (linear_settings.type == LinearSolverType::gmres_amg_block) {
    const AmgBlock block = amg_block(scene, *built);
    linear->set_amg_block(block.begin, block.end);
    linear->set_near_null_space(block.modes);
    linear->set_node_coordinates(block.coordinates);
    log::info("gmres_amg_block: AMG on body '{}' ({} unknowns), UMFPACK LU on the other {}", block.body, block.end - block.begin,
              model.dofs.size() - (block.end - block.begin));
  }
  // Ranks: MPI is initialised here when the CLI has not. Every rank holds u;
  // elements are split; rank 0 writes.
  initialize_parallel();
  model.rank = parallel::rank();
  model.ranks = parallel::size();
  // Every rank refuses alike (no collective has run): these solvers would see one rank's rows only.
  if (one_rank_only(linear_settings.type) && model.ranks > 1)
    throw InputError(fmt::format("{}: linear solver {} runs on one MPI rank in this version (solver.linear.type, or "
                                 "--linear-solver); on {} ranks use direct, gmres_ilu or gmres_amg",
                                 file, linear_solver_name(linear_settings.type), model.ranks));
  const bool writes = model.rank == 0;
  if (!writes) log::set_level(log::Level::warn);
  // Threads of the element loops: the option, else $STENTSIM_THREADS, else this node's cores over the ranks.
  const AssemblyThreads threads(options.threads ? *options.threads : default_assembly_threads(model.ranks));
  log::info("linear solver: {}; {} MPI rank(s), {} assembly thread(s) per rank", linear->describe(), model.ranks, assembly_threads());
  if (linear_settings.type == LinearSolverType::direct && model.ranks > 1)
    log::info("direct solver on {} ranks: the assembled matrix is gathered on rank 0 and factored there with "
              "UMFPACK (serial; memory and time of one rank); use gmres_ilu or gmres_amg for large models", model.ranks);

  const std::filesystem::path scratch = std::filesystem::temp_directory_path() / fmt::format("stentsim_rank{}_{}", model.rank, ::getpid());
  ResultsWriter writer(writes ? out_dir : scratch);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
  auto frame = [&](double t) {
    std::vector<std::pair<std::string, MeshData>> meshes;
    for (const auto& [name, body] : built->bodies) meshes.emplace_back(name, solid_output(*body, u));
    // Beams: their own VTU per frame (sampled centerline, Radius, triads, section forces) in the same PVD.
    for (const auto& [name, beam] : built->beams) meshes.emplace_back(name, beams::beam_output_mesh(*beam, u));
    for (const auto& [prefix, o] : observers) o->decorate(meshes, u);
    writer.write_frame(writer.frames(), t, meshes);
  };
  std::vector<std::string> columns{"step", "time", "dt", "load_factor", "newton_iterations", "linear_iterations", "step_cuts",
                                   "wall_time_s", "assembly_s", "linear_solve_s"};
  for (const auto& [name, p] : built->pressures) columns.push_back("pressure_" + name);
  for (const auto& [prefix, o] : observers)
    for (const auto& c : o->history_columns()) columns.push_back(c);
  const std::filesystem::path checkpoint_file = out_dir / "checkpoint.bin";
  const int checkpoint_every = options.checkpoint_every.value_or(scene.checkpoint_every);
  RunCounters counters;
  double t_last = stepping.t_start;
  const std::map<std::string, std::string> scene_hashes = scene_state_hashes(scene);  // the files as this run read them
  if (options.restart) {
    const std::filesystem::path from = options.restart->empty() ? checkpoint_file : *options.restart;
    const HistoryArchive ck = HistoryArchive::read(from);
    // Before the state's size: another scene's checkpoint is named as such.
    check_fingerprint(ck, state_fingerprint(scene, scene_hashes, ck.get_scalar("solver/time")), from.string(),
                      scene.file.string());
    // The history's columns (the scene's pressures and QoIs) must be the ones this run writes.
    const std::string history = ck.get_text("results/history"), header = fmt::format("{}", fmt::join(columns, ","));
    if (history.substr(0, history.find('\n')) != header)
      throw InputError(fmt::format("{}: the checkpoint's history.csv has other columns than {} writes (its pressures or "
                                   "QoIs changed); a checkpoint resumes only the run that wrote it: run without --restart",
                                   from.string(), scene.file.string()));
    const SolverCheckpoint state = SolverCheckpoint::get(ck, model.dofs.size());
    u = state.u;
    model.load_history(ck);
    writer.load(ck);
    for (const auto& [prefix, o] : observers) o->load(ck, prefix);
    counters = state.counters;
    t_last = state.time;
    stepping.t_start = t_last;
    stepping.dt_first = state.next_dt;
    stepping.first_step = counters.steps;
    stepping.last_increment = state.last_increment;
    stepping.last_dt = state.last_dt;
    log::info("restart from {}: step {}, t = {:.6g}, next dt = {:.3g}", from.string(), counters.steps, t_last, stepping.dt_first);
  } else {
    frame(stepping.t_start);
  }
  for (const auto& [prefix, o] : observers) o->start(u, options.restart.has_value());

  if (!options.restart) writer.history_header(columns);
  const LoadCurve* lf = scene.load_factor_curve.empty() ? nullptr : &scene.curves.at(scene.load_factor_curve);
  auto on_step = [&](const StepRecord& r) {
    ++counters.steps;
    t_last = r.time;
    counters.newton_iterations += r.newton_iterations;
    counters.linear_iterations += r.linear_iterations;
    counters.step_cuts += r.cuts;
    counters.predicted_steps += r.predicted ? 1 : 0;
    if (r.at_floor) {
      ++counters.floor_steps;
      counters.worst_floor = std::max(counters.worst_floor, r.residual_at_floor / r.force_magnitude);
    }
    for (const auto& [prefix, o] : observers) o->step(r, u);
    std::vector<double> row{static_cast<double>(r.step), r.time, r.dt, lf ? (*lf)(r.time) : r.time,
                            static_cast<double>(r.newton_iterations), static_cast<double>(r.linear_iterations),
                            static_cast<double>(r.cuts), r.wall_seconds, r.assembly_seconds, r.linear_seconds};
    for (const auto& [name, p] : built->pressures) row.push_back(p->pressure(r.time));
    for (const auto& [prefix, o] : observers)
      for (double v : o->history_values()) row.push_back(v);
    writer.history_row(row);
    bool at_stop = same_time(r.time, stepping.t_end, stepping.t_end);
    for (double s : stepping.stops) at_stop = at_stop || same_time(r.time, s, stepping.t_end);
    if (r.step % scene.output_every == 0 || at_stop) frame(r.time);
    if (checkpoint_every > 0 && r.step % checkpoint_every == 0 && writes) {
      HistoryArchive ck;
      SolverCheckpoint{u, r.time, r.next_dt, r.increment, r.dt, counters}.put(ck);
      put_fingerprint(ck, state_fingerprint(scene, scene_hashes, r.time));
      for (const auto& [prefix, o] : observers) o->save(ck, prefix);
      model.save_history(ck);
      writer.save(ck);
      ck.write(checkpoint_file);
      log::debug("checkpoint at step {} (t = {:.6g}): {}", r.step, r.time, checkpoint_file.string());
    }
  };
  // The stall message names the load the run could not go beyond ("no converged state beyond p = ...").
  stepping.describe_load = [&](double t) {
    std::string d;
    for (const auto& [name, p] : built->pressures) d += fmt::format("{}p = {:.6g} MPa", d.empty() ? "" : ", ", p->pressure(t));
    if (d.empty()) d = fmt::format("t = {:.6g}", t);
    return fmt::format("{} (load factor {:.6g}, t = {:.6g})", d, lf ? (*lf)(t) : t, t);
  };
  GlobalSystem system(model.constraints);
  int status = 0;
  std::string failure;
  try {
    run_load_steps(model, system, *linear, u, stepping, scene.newton, on_step);
  } catch (const ComputeError& e) {
    failure = e.what();
    status = 2;
    // The stalled step's failed attempts are in no step record; the totals count every attempt.
    if (const auto* stall = dynamic_cast<const LoadStepStall*>(&e)) {
      counters.newton_iterations += stall->newton_iterations;
      counters.linear_iterations += stall->linear_iterations;
      counters.step_cuts += stall->cuts;
    }
    log::error("{}", failure);
    if (std::abs(writer.last_time() - t_last) > 1e-12) frame(t_last);  // the last converged state
    log::error("the last converged state (t = {:.6g}) is in {}", t_last, (out_dir / "results.pvd").string());
  }
  const RunEnd end{status == 0, t_last, &u};
  for (const auto& [prefix, o] : observers) o->summarize(summary, end);
  summary.set_text("status", status == 0 ? "completed" : "failed");
  if (!failure.empty()) summary.note("failure", failure);
  summary.set("steps", static_cast<double>(counters.steps));
  summary.set("newton_iterations", static_cast<double>(counters.newton_iterations));
  summary.set("linear_iterations", static_cast<double>(counters.linear_iterations));
  summary.set("step_cuts", static_cast<double>(counters.step_cuts));
  summary.set("predicted_steps", static_cast<double>(counters.predicted_steps));
  // Steps taken as converged at the residual floor, and their largest |R| / |m| (newton.hpp).
  summary.set("floor_steps", static_cast<double>(counters.floor_steps));
  if (counters.floor_steps > 0) summary.set("worst_floor_residual", counters.worst_floor);
  summary.set("dofs", static_cast<double>(model.dofs.size()));
  summary.set("assembly_threads", static_cast<double>(assembly_threads()));
  summary.set("final_time", t_last, "s");
  summary.note("scene", file);
  summary.note("linear_solver", linear->describe());
  for (std::size_t i = 0; i < built->notes.size(); ++i) summary.note(fmt::format("material_{}", i), built->notes[i]);
  // Every rank's own peak memory, gathered on rank 0 (a study sums them over ranks);
  // the run's peak_memory_mb is that sum.
  Eigen::VectorXd rank_memory = Eigen::VectorXd::Zero(model.ranks);
  rank_memory[model.rank] = peak_memory_mb_self();
  parallel::sum(rank_memory);
  summary.set("peak_memory_mb_per_rank", std::vector<double>(rank_memory.data(), rank_memory.data() + rank_memory.size()), "MB");
  summary.set_run(std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count(), rank_memory.sum());
  if (writes) summary.write(out_dir / "summary.yaml");
  else std::filesystem::remove_all(scratch);
  log::info("solve {}: {} steps, {} Newton iterations; results in {}", status == 0 ? "completed" : "FAILED", counters.steps,
            counters.newton_iterations, out_dir.string());
  return status;
}

int solve_scene(const std::filesystem::path& scene_yaml, const SolveOptions& options) {
  const SceneDesc scene = read_scene(scene_yaml);
  Summary summary;
  return solve(scene, options, summary);
}

}  // namespace stentsim::solver
