#pragma once
// A case: one YAML file (patient or scene) with sections input, device, mesh,
// fibers, simulation, output. The whole file is validated before anything
// runs; every section keeps its raw YAML so that each stage hashes exactly the
// slice it depends on.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>

#include "common/stenosis_site.hpp"
#include "meshing/generic_artery.hpp"
#include "meshing/patient_mesh.hpp"
#include "solver/linalg/linear_solver.hpp"



namespace stentsim::workflows {

enum class Scene { free_expansion, generic_artery, patient };
const char* to_string(Scene s);

/// Settings of the sections owned by the solve stage and its preprocessing
/// (mesh, fibers, simulation, output), validated with units. Device and input
/// sections are validated by their stages' own parsers.
/// The case's `mesh:` section (patient wall mesh; `mesh.generic` is the generic artery).
using MeshSettings = meshing::PatientMeshOptions;


struct FiberSettings {
  double media_angle = 0.0, intima_angle = 0.0, adventitia_angle = 0.6981317007977318;  // rad (40 deg)
  bool tension_only = false;
  double centerline_weight = 0.5;          // patient: centerline tangent vs grad l (fibers/harmonic_fibers.hpp)
  solver::LinearSolverType linear_solver = solver::LinearSolverType::gmres_amg;  // the Laplace solves (patient scene)
  bool laplace_on_corners = true;          // tet10: longitudinal problem on the corner nodes (t stays quadratic)
};

struct SimulationSettings {
  double pressure_max = 1.01;              // MPa
  double diastolic_pressure = 85 * 133.322387415e-6;  // MPa
  double phase_duration = 1.0;             // s of pseudo-time per phase
  int load_steps = 100;                    // per phase, initial
  // per phase, the fewest: the step grows after easy steps up to the phase /
  // min_load_steps (0: as load_steps, the step never grows)
  int min_load_steps = 0;
  solver::LinearSolverType linear_solver = solver::LinearSolverType::direct;
  int ranks = 1;
  double balloon_end_springs = 100.0;      // N/mm^3
  double cut_springs = 1000.0;             // N/mm^3
  double beam_penalty = 10.0;              // N/mm^2
  double surface_penalty = 5.0;            // N/mm^3
};

struct OutputSettings {
  int every = 1;  // write results every N converged steps
  // a solve checkpoint every N converged steps (0: none), from which the solve stage
  // resumes an interrupted or failed attempt
  int checkpoint_every = 1;
};

struct CaseConfig {
  std::filesystem::path file;
  std::string name;
  Scene scene = Scene::patient;
  std::filesystem::path work_dir;
  YAML::Node root;  // the whole file, for stage configuration slices
  MeshSettings mesh;
  meshing::GenericArterySpec generic_artery;  // paper Case 1 (DESIGN §5)
  FiberSettings fibers;
  SimulationSettings simulation;
  OutputSettings output;
  /// The one stenosis rule (`stenosis:`; scenes with an input): the segmentation's
  /// region of interest and wall synthesis, the centerline stage's lesions
  /// and the placement's site.
  StenosisRule stenosis;
  /// The device is warped along a placement's balloon centerline (DESIGN.md §3):
  /// a patient, or a free expansion given a vessel (`input:`) whose centerline
  /// it follows, as the paper's curved device (Section 3.2).
  bool placed = false;

  /// The raw YAML of a section ("device.stent"); an empty map when absent.
  YAML::Node section(const std::string& dotted) const;
};

/// Reads and validates a case file. Throws InputError naming file:line, key
/// and expectation for unknown keys, wrong types, missing or out-of-range values.
CaseConfig load_case(const std::filesystem::path& file);

}  // namespace stentsim::workflows
