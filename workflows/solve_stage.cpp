#include "workflows/solve_stage.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <optional>
#include <limits>
#include <fstream>
#include <sstream>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/log.hpp"
#include "common/mesh_data.hpp"
#include "common/mesh_tags.hpp"
#include "device_gen/stent_design.hpp"
#include "common/child_process.hpp"
#include "solver/app/checkpoint.hpp"
#include "solver/app/solve.hpp"
#include "solver/io/scene.hpp"
#include "solver/linalg/linear_solver.hpp"

namespace stentsim::workflows {
namespace fs = std::filesystem;
namespace {

/// Where the scene reads the earlier stages' artifacts.
struct Artifacts {
  std::string balloon, stent, artery, fibers;
};

/// The load phases (DESIGN.md §5): with an artery a prestress phase first
/// (the diastolic pressure on the endothelium, held to the end); then inflation of the balloon
/// to p_max and deflation, each one phase long. "prestress", "max" and
/// "after" are the ends of the phases.
struct Phases {
  bool artery;
  bool patient;  // segmented three-layer artery
  bool placed;   // device warped along the placement's centerline (patient, curved free expansion)
  double T;
  double prestress() const { return artery ? T : 0.0; }
  double max() const { return prestress() + T; }
  double after() const { return prestress() + 2 * T; }
  std::string times() const {
    return artery ? fmt::format("{{prestress: {:.17g}, max: {:.17g}, after: {:.17g}}}", prestress(), max(), after())
                  : fmt::format("{{max: {:.17g}, after: {:.17g}}}", max(), after());
  }
};

/// A YAML double-quoted scalar (names and paths may hold ':', '#', ',', '}').
std::string quoted(const std::string& text) {
  std::string q = "\"";
  for (char ch : text) {
    if (ch == '"' || ch == '\\') q += '\\';
    q += ch;
  }
  return q + "\"";
}

std::string selector(int face_group) { return fmt::format("{{cell_array: {{name: FaceGroup, value: {}}}}}", face_group); }

std::string header(const CaseConfig& c, const Phases& ph) {
  return fmt::format(
      "# Written by the solve stage of the case {case} (scene {scene}). Re-run by hand:\n"
      "#   stentsim solve scene.yaml --out DIR\n"
      "# {what}\n"
      "# Phases (DESIGN.md §5): {phases}.\n"
      "description: {desc}\n\n",
      fmt::arg("case", c.file.string()), fmt::arg("scene", to_string(c.scene)),
      fmt::arg("desc", quoted(fmt::format("{} '{}', p_max {:g} MPa", to_string(c.scene), c.name, c.simulation.pressure_max))),
      fmt::arg("what", ph.patient  ? "Patient (paper 4.2): segmented artery (intima, media, adventitia) with the fibers stage's "
                                     "fibers, balloon and stent warped along the placement's centerline; stent–balloon and "
                                     "stent–artery beam-to-surface, balloon–artery surface-to-surface contact."
                       : ph.artery ? "Generic artery (paper 4.1): artery (media, adventitia) with fibers, balloon, stent; "
                                     "stent–balloon and stent–artery beam-to-surface, balloon–artery surface-to-surface contact."
                       : ph.placed ? "Curved free expansion (paper 3.2): balloon + stent warped along the placement's centerline, "
                                     "no artery; stent–balloon beam-to-surface contact."
                                   : "Free expansion (paper 3.1): balloon + stent, stent–balloon beam-to-surface contact."),
      fmt::arg("phases", ph.artery ? fmt::format("prestress to t {:g} (diastolic pressure, held), inflation to t {:g} (\"max\"), "
                                                 "deflation to t {:g} (\"after\")",
                                                 ph.prestress(), ph.max(), ph.after())
                                   : fmt::format("inflation to t {:g} (\"max\"), deflation to t {:g} (\"after\")", ph.max(),
                                                 ph.after())));
}

std::string bodies(const CaseConfig& c, const Artifacts& a, const Phases& ph) {
  std::string y = fmt::format(
      "bodies:\n"
      "  - name: balloon\n"
      "    mesh: {{file: {b}}}\n"
      "    materials:\n"
      "      - preset: balloon          # neo-Hooke E 17 MPa, ν 0; longitudinal and circumferential fibers; viscous branch\n"
      "{frames}"
      "  - name: stent\n"
      "    beam: {{file: {st}, material: stent, joints: rigid}}   # App. C elasto-plastic beams\n",
      fmt::arg("b", quoted(a.balloon)), fmt::arg("st", quoted(a.stent)),
      fmt::arg("frames", ph.placed ? fmt::format("    fiber_frames:                # warped balloon: the balloon stage's frames per cell; "
                                                  "fibers from the material's angles\n"
                                                  "      {{file: {}, fibers: none}}\n",
                                                  quoted(a.balloon))
                                    : "    fiber_frames:                # the straight balloon's axis: frames exact at every Gauss point\n"
                                      "      cylindrical: {origin: [0, 0, 0], axis: [0, 0, 1]}\n"));
  if (ph.artery) {
    const std::string tension = c.fibers.tension_only ? ", tension_only_fibers: true" : "";
    y += fmt::format(
        "  - name: artery\n"
        "    mesh: {{file: {art}}}\n"
        "    material_array: Layer\n"
        "    materials:                   # App. B: coupled neo-Hooke + two fiber families + viscous branch\n"
        "{intima}"
        "      - {{tag: {media}, preset: media{t}}}\n"
        "      - {{tag: {adv}, preset: adventitia{t}}}\n"
        "    fiber_frames: {{file: {fib}}}   # the fibers stage's frames and Fiber1, Fiber2\n",
        fmt::arg("art", quoted(a.artery)), fmt::arg("fib", quoted(a.fibers)), fmt::arg("media", static_cast<int>(tags::media)),
        fmt::arg("adv", static_cast<int>(tags::adventitia)), fmt::arg("t", tension),
        fmt::arg("intima", ph.patient ? fmt::format("      - {{tag: {}, preset: media{}}}   # intima: as media (DESIGN.md §5)\n",
                                                    static_cast<int>(tags::intima), tension)
                                      : ""));
  }
  return y + "\n";
}

std::string load_curves(const Phases& ph) {
  std::string y = "load_curves:\n";
  if (ph.artery)
    y += fmt::format("  prestress: [[0, 0], [{:.17g}, 1], [{:.17g}, 1]]\n", ph.prestress(), ph.after()) +
         fmt::format("  inflation: [[0, 0], [{:.17g}, 0], [{:.17g}, 1], [{:.17g}, 0]]\n", ph.prestress(), ph.max(), ph.after());
  else
    y += fmt::format("  inflation: [[0, 0], [{:.17g}, 1], [{:.17g}, 0]]\n", ph.max(), ph.after());
  return y + "\n";
}

std::string springs(const std::string& name, const std::string& body, int group, double k) {
  return fmt::format(
      "  - name: {}\n    type: springs\n    body: {}\n    surface: {}\n    stiffness: {:.17g} N/mm^3\n", name, body,
      selector(group), k);
}

std::string pressure(const std::string& name, const std::string& body, int group, double value, const std::string& curve,
                     const std::string& what) {
  return fmt::format("  - name: {}\n    type: pressure                 # {}\n    body: {}\n    surface: {}\n"
                     "    value: {:.17g} MPa\n    curve: {}\n",
                     name, what, body, selector(group), value, curve);
}

std::string conditions(const CaseConfig& c, const Phases& ph) {
  const SimulationSettings& s = c.simulation;
  std::string y = "conditions:\n" + pressure("inflation", "balloon", tags::balloon_inner, s.pressure_max, "inflation",
                                             "follower load on the balloon's inner face");
  y += springs("balloon_end_proximal", "balloon", tags::balloon_end_proximal, s.balloon_end_springs);
  y += springs("balloon_end_distal", "balloon", tags::balloon_end_distal, s.balloon_end_springs);
  y += "  - name: stent_fixations\n"
       "    type: direction                # radial fixation nodes move only radially, the axial one keeps d·u = 0\n"
       "    body: stent\n"
       "    node: fixations\n"
       "    direction: file\n";
  if (ph.artery) {
    y += pressure("diastolic", "artery", tags::endothelium, s.diastolic_pressure, "prestress",
                  "follower load on the endothelium, Nanson's formula (DESIGN.md §5)");
    y += springs("cut_proximal", "artery", tags::proximal_cut, s.cut_springs);
    y += springs("cut_distal", "artery", tags::distal_cut, s.cut_springs);
  }
  return y + "\n";
}

std::string beam_pair(const std::string& name, const std::string& solid, int group, double eps, const Phases& ph) {
  return fmt::format(
      "  - name: {}\n    type: beam_to_surface\n    beam: stent\n    solid: {}\n    surface: {}\n"
      "    penalty: {:.17g} N/mm^2\n    times: {}\n",
      name, solid, selector(group), eps, ph.times());
}

std::string contact(const CaseConfig& c, const Phases& ph) {
  const SimulationSettings& s = c.simulation;
  std::string y = "contact:\n" + beam_pair("stent_balloon", "balloon", tags::balloon_outer, s.beam_penalty, ph);
  if (ph.artery) {
    y += beam_pair("stent_artery", "artery", tags::endothelium, s.beam_penalty, ph);
    y += fmt::format(
        "  - name: balloon_artery\n"
        "    type: surface_to_surface       # the balloon (finer) is the slave (DESIGN.md §8)\n"
        "    slave: {{body: balloon, surface: {}}}\n"
        "    master: {{body: artery, surface: {}}}\n"
        "    penalty: {:.17g} N/mm^3\n"
        "    times: {}\n",
        selector(tags::balloon_outer), selector(tags::endothelium), s.surface_penalty, ph.times());
  }
  return y + "\n";
}

std::string solver_section(const CaseConfig& c, const Phases& ph) {
  const double dt = ph.T / c.simulation.load_steps;
  const double dt_max = c.simulation.min_load_steps > 0 ? ph.T / c.simulation.min_load_steps : dt;
  return fmt::format(
      "solver:\n"
      "  time: {{start: 0, end: {end:.17g}, dt: {dt:.17g}, dt_max: {dtmax:.17g}, dt_min: {dtmin:.17g}}}\n"
      "  # residual_absolute: the stent's residual does not go below ~5e-10 N in double precision\n"
      "  # (E 380,000 MPa beams, coordinates ~10 mm); with the solver's 1e-10 N the unloaded\n"
      "  # device in prestress stalls Newton at that floor.\n"
      "  # max_iterations: with contact a step's active set can take 20 damped iterations to settle\n"
      "  # before Newton converges in a few (the patient example's inflation above 0.6 MPa).\n"
      "  # floor_tolerance: the balloon-artery contact's residual floor is a few 1e-6 N, against\n"
      "  # the artery's own forces in balance of only ~0.4 N (the patient example at 1 MPa).\n"
      "  # floor_reduction: the patient example's deflation creeps along that floor by 10-25 % per\n"
      "  # damped iteration; at 0.5 its steps stop there 4-5 iterations earlier and grow, and the\n"
      "  # example's QoIs stay within a unit of their last printed digit.\n"
      "  newton: {{max_iterations: 40, residual_tolerance: 1.0e-8, residual_absolute: 1.0e-8, increment_tolerance: 1.0e-8, "
      "floor_tolerance: 1.0e-4, floor_reduction: 0.5}}\n"
      "  linear: {{type: {lin}}}\n\n"
      "output:\n  every: {every}\n\n",
      fmt::arg("end", ph.after()), fmt::arg("dt", dt), fmt::arg("dtmax", dt_max), fmt::arg("dtmin", dt * 1e-4),
      fmt::arg("lin", solver::linear_solver_name(c.simulation.linear_solver)), fmt::arg("every", c.output.every));
}

std::string qois(const CaseConfig& c, const Phases& ph) {
  // Balloon profiles at fractions of p_max on the way up (the paper's balloon figure).
  std::string fractions;
  for (double f : {0.2, 0.4, 0.6, 0.8, 1.0})
    fractions += fmt::format("{}{:.17g}", fractions.empty() ? "" : ", ", f == 1.0 ? c.simulation.pressure_max : f * c.simulation.pressure_max);
  std::string y = fmt::format(
      "qoi:\n"
      "  - name: stent\n"
      "    type: stent_expansion          # ring diameters, recoil, dogboning (DESIGN.md §8), centroid curvature\n"
      "    body: stent\n"
      "    pressure: inflation\n"
      "    times: {times}\n",
      fmt::arg("times", ph.times()));
  // The balloon's profile along its axis needs a straight balloon.
  if (!ph.placed)
    y += fmt::format(
      "  - name: balloon\n"
      "    type: balloon_profile          # outer diameter along the (straight) axis\n"
      "    body: balloon\n"
      "    surface: {outer}\n"
      "    axis: {{origin: [0, 0, 0], direction: [0, 0, 1]}}\n"
      "    pressure: inflation\n"
      "    pressures: [{fr}]          # MPa\n"
      "    times: {times}\n",
      fmt::arg("times", ph.times()), fmt::arg("outer", selector(tags::balloon_outer)), fmt::arg("fr", fractions));
  if (ph.artery)
    y += fmt::format(
        "  - name: artery\n"
        "    type: layer_stresses           # max principal Cauchy stress per layer: Gauss-point maximum and nodal-averaged\n"
        "    body: artery\n"
        "    layer_array: Layer\n"
        "    layers: {{{intima}media: {media}, adventitia: {adv}}}\n"
        "    endothelium: {endo}\n"
        "    times: {times}\n",
        fmt::arg("media", static_cast<int>(tags::media)), fmt::arg("adv", static_cast<int>(tags::adventitia)),
        fmt::arg("endo", selector(tags::endothelium)), fmt::arg("times", ph.times()),
        fmt::arg("intima", ph.patient ? fmt::format("intima: {}, ", static_cast<int>(tags::intima)) : ""));
  if (ph.artery)
    y += fmt::format(
        "  - name: malapposition\n"
        "    type: malapposition            # strut-to-endothelium gaps; malapposed above the strut thickness (DESIGN.md §8)\n"
        "    body: stent\n"
        "    solid: artery\n"
        "    surface: {endo}\n"
        "    times: {times}\n",
        fmt::arg("endo", selector(tags::endothelium)), fmt::arg("times", ph.times()));
  if (ph.artery)
    y += fmt::format(
        "  - name: lumen\n"
        "    type: lumen_area               # cross-section areas in the planes of the stent's rings and between them\n"
        "    stent: stent\n"
        "    body: artery\n"
        "    surface: {endo}\n"
        "    times: {times}\n",
        fmt::arg("endo", selector(tags::endothelium)), fmt::arg("times", ph.times()));
  return y;
}

Phases phases(const CaseConfig& c) {
  return {c.scene != Scene::free_expansion, c.scene == Scene::patient, c.placed, c.simulation.phase_duration};
}

/// The comments and description (the case's name and file: not physics).
std::string scene_header(const CaseConfig& c) { return header(c, phases(c)); }

/// Everything the solve computes from, with the artifacts' paths as given.
std::string scene_body(const CaseConfig& c, const Artifacts& a) {
  const Phases ph = phases(c);
  return bodies(c, a, ph) + load_curves(ph) + conditions(c, ph) + contact(c, ph) + solver_section(c, ph) + qois(c, ph);
}

/// The scene text with the artifacts' paths as given.
std::string scene_text(const CaseConfig& c, const Artifacts& a) {
  return scene_header(c) + scene_body(c, a);
}

/// The artifacts, as paths relative to `dir` (the work folder's solve/) or absolute under `work`.
Artifacts artifacts(const CaseConfig& c, const fs::path& work) {
  auto at = [&](const char* rel) { return work.empty() ? std::string("../") + rel : (work / rel).string(); };
  Artifacts a{at("balloon/balloon.vtu"), at("stent/stent.vtu"), "", ""};
  if (c.scene != Scene::free_expansion) a.artery = at("mesh/artery.vtu"), a.fibers = at("fibers/fibers.vtu");
  return a;
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

/// Where the solve runs and what it resumes from. The solve writes into the stage's resume
/// folder, with a checkpoint every output.checkpoint_every steps, so that an attempt that was
/// interrupted (Ctrl-C, a killed job) or failed continues from its last checkpoint when the
/// stage runs again. A checkpoint that cannot resume this scene (its bodies, conditions,
/// contact, input files or loads up to its time differ, or it cannot be read) is dropped
/// with the reason in the log, and the run starts over in an emptied folder; so is one found
/// with checkpoints switched off (checkpoint_every 0).
struct SolveRun {
  fs::path dir;
  std::optional<fs::path> restart;
};

void empty_folder(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(dir)) fs::remove_all(entry.path());
}

SolveRun prepare_solve_run(const solver::SceneDesc& scene, const fs::path& resume_dir, int checkpoint_every) {
  SolveRun run{resume_dir, std::nullopt};
  const fs::path checkpoint = resume_dir / "checkpoint.bin";
  if (fs::exists(checkpoint)) {
    const std::string refusal = checkpoint_every > 0 ? solver::checkpoint_refusal(scene, checkpoint)
                                                     : std::string("output.checkpoint_every is 0");
    if (refusal.empty()) {
      log::info("resuming the solve from the checkpoint of an earlier attempt: {}", checkpoint.string());
      run.restart = checkpoint;
      return run;
    }
    log::info("not resuming from {}: {}; the solve starts from the beginning", checkpoint.string(), refusal);
  }
  empty_folder(resume_dir);
  return run;
}

/// A second name `to` for the file `from`: a hard link (a copy where the file system has
/// none). The results writer replaces files, never changes them in place, so both names
/// keep the content of the moment.
void link_or_copy(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::remove(to, ec);
  fs::create_hard_link(from, to, ec);
  if (!ec) return;
  fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
  if (ec) throw ComputeError(fmt::format("cannot copy {} to {}: {}", from.string(), to.string(), ec.message()));
}

/// The solve's outputs into the stage's output folder: moved when it finished (its checkpoint
/// first removed, so that nothing resumes a finished run; the runner then removes the resume
/// folder), hard-linked with its summary when it did not, so that failed/solve/ holds them
/// while the resume folder keeps its checkpoint and frames for the next attempt.
void hand_over_results(const fs::path& from, const fs::path& to, bool finished) {
  if (finished) fs::remove(from / "checkpoint.bin");
  for (const char* name : {"results.pvd", "history.csv", "summary.yaml", "results"}) {
    const fs::path src = from / name, dst = to / name;
    if (!fs::exists(src)) continue;
    if (finished) {
      if (std::string(name) != "summary.yaml") fs::rename(src, dst);  // the stage's summary is the runner's to write
      continue;
    }
    if (!fs::is_directory(src)) {
      link_or_copy(src, dst);
      continue;
    }
    fs::create_directories(dst);
    for (const auto& entry : fs::directory_iterator(src)) link_or_copy(entry.path(), dst / entry.path().filename());
  }
}

}  // namespace

std::string contact_face_size_warning(const fs::path& artery_vtu, double strut_diameter) {
  const MeshData m = read_vtu(artery_vtu.string());
  const auto groups = m.cell_data.find(tags::kFaceGroup);
  if (groups == m.cell_data.end()) return {};  // the solver names the missing array
  std::size_t faces = 0, small = 0;
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    if (static_cast<int>(groups->second.at(c)) != tags::endothelium) continue;
    const auto nodes = m.cell(c);
    const std::size_t corners = m.cell_types[c] == CellType::quad ? 4 : 3;
    double shortest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < corners && corners <= nodes.size(); ++i)
      shortest = std::min(shortest, (m.points[nodes[i]] - m.points[nodes[(i + 1) % corners]]).norm());
    ++faces;
    if (shortest < strut_diameter) ++small;
    smallest = std::min(smallest, shortest);
  }
  if (small == 0) return {};
  const std::string msg = fmt::format(
      "{} of {} endothelium faces of {} have an edge shorter than the strut diameter {:g} mm (shortest {:.3g} mm); "
      "the paper keeps contact faces no smaller than the struts (2.5): coarsen the artery mesh where the stent lies",
      small, faces, artery_vtu.string(), strut_diameter, smallest);
  log::warn("{}", msg);
  return msg;
}


std::string solve_scene_text(const CaseConfig& c) { return scene_text(c, artifacts(c, {})); }

pipeline::Stage solve_stage(const CaseConfig& c) {
  pipeline::Stage s;
  s.name = "solve";
  s.inputs = {"balloon/balloon.vtu", "stent/stent.vtu"};
  if (c.scene != Scene::free_expansion) s.inputs.insert(s.inputs.end(), {"mesh/artery.vtu", "fibers/fibers.vtu"});
  s.outputs = {"solve/scene.yaml", "solve/results.pvd", "solve/results/", "solve/history.csv"};
  s.version = "1";
  const std::string text = solve_scene_text(c);  // input errors before anything runs
  // The scene's body is everything the solve depends on besides its input
  // files (not the case's name or folder; the rank count changes no result, DESIGN.md §7).
  s.config = scene_body(c, artifacts(c, {}));
  const CaseConfig cfg = c;
  ConfigMap stent(c.section("device.stent"), std::make_shared<const fs::path>(c.file), "device.stent");
  const double strut_diameter = 2 * device_gen::parse_stent_design(stent).strut_radius;
  s.run = [text, cfg, strut_diameter](pipeline::StageContext& ctx) {
    const fs::path scene_out = ctx.output("solve/scene.yaml");
    files::write_atomic(scene_out, text);
    const fs::path out_dir = scene_out.parent_path();
    // Read as the file it becomes (work/solve/scene.yaml), so its relative paths hold.
    const fs::path final_scene = ctx.work_dir() / "solve" / "scene.yaml";
    const std::string face_warning =
        cfg.scene == Scene::free_expansion ? "" : contact_face_size_warning(ctx.input("mesh/artery.vtu"), strut_diameter);
    if (!face_warning.empty()) ctx.summary().note("warning_contact_face_size", face_warning);
    // MPI: a copy of the scene with absolute paths, run by `stentsim solve` under mpirun.
    const fs::path run_scene = out_dir.parent_path() / "run_scene.yaml";
    const bool mpi = cfg.simulation.ranks > 1;
    if (mpi) files::write_atomic(run_scene, scene_text(cfg, artifacts(cfg, ctx.work_dir())));
    const solver::SceneDesc scene = mpi ? solver::read_scene(run_scene) : solver::read_scene(text, final_scene);
    SolveRun run = prepare_solve_run(scene, ctx.resume_dir(), cfg.output.checkpoint_every);
    int status = 0;
    std::string mpi_end;
    int mpi_exit = 0;
    if (!mpi) {
      solver::SolveOptions o;
      o.output_dir = run.dir;
      o.restart = run.restart;
      o.checkpoint_every = cfg.output.checkpoint_every;
      try {
        status = solver::solve(scene, o, ctx.summary());
      } catch (const InputError& e) {
        if (!run.restart) throw;
        // A checkpoint the fingerprint accepted but the model cannot take (its state or
        // history has another size or kind): the run starts over.
        log::info("not resuming from {}: {}; the solve starts from the beginning", run.restart->string(), e.what());
        empty_folder(run.dir);
        o.restart.reset();
        ctx.summary() = Summary{};
        status = solver::solve(scene, o, ctx.summary());
      }
    } else {
      std::vector<std::string> argv = mpi_launcher(cfg.simulation.ranks);
      for (const std::string& a : {process::self_executable().string(), std::string("solve"), run_scene.string(),
                                  std::string("--out"), run.dir.string(), std::string("--checkpoint-every"),
                                  std::to_string(cfg.output.checkpoint_every)})
        argv.push_back(a);
      if (run.restart) argv.insert(argv.end(), {"--restart", run.restart->string()});
      const auto start = std::chrono::steady_clock::now();
      const pid_t pid = process::spawn_exec(argv);
      const process::ChildEnd end = process::wait_with_limit(pid, start, 1e9);
      if (!end.ok()) status = 1, mpi_end = end.describe(), mpi_exit = end.exit_code;
      else ctx.summary() = Summary::read(run.dir / "summary.yaml");
      if (!face_warning.empty()) ctx.summary().note("warning_contact_face_size", face_warning);
    }
    hand_over_results(run.dir, out_dir, status == 0);
    if (status == 0) return;
    const std::string kept = (ctx.work_dir() / "failed" / "solve" / "solve").string();
    const std::string resume = fs::exists(run.dir / "checkpoint.bin")
                                   ? fmt::format("; `stentsim run` continues from its last checkpoint ({}) unless the "
                                                 "bodies, conditions, contact or loads change",
                                                 (run.dir / "checkpoint.bin").string())
                                   : std::string();
    if (mpi && mpi_exit == 2)  // `stentsim solve` exits 2 on a bad input (cli/main.cpp); its log says which
      throw InputError(fmt::format("the MPI solve ({} ranks) refused its input (exit status 2; the log names the file and "
                                   "field): {}",
                                   cfg.simulation.ranks, (ctx.work_dir() / "logs" / "solve.log").string()));
    if (mpi)
      throw ComputeError(fmt::format("the MPI solve ({} ranks) ended with {} (the log says where and why); what it wrote "
                                     "is kept in {}{}",
                                     cfg.simulation.ranks, mpi_end, kept, resume));
    throw ComputeError(fmt::format("the solve did not finish (the log says where and why); its last converged state, "
                                   "history.csv and summary are kept in {}{}",
                                   kept, resume));
  };
  return s;
}

}  // namespace stentsim::workflows
