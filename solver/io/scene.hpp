#pragma once
// The scene file (YAML): bodies (mesh + material per cell tag + fiber
// frames, or beams), load curves, conditions, contact pairs, solver settings,
// outputs and quantities of interest. read_scene validates everything with
// errors naming file:line:key; examples/tube_inflation.yaml shows every part,
// examples/contact_*.yaml the contact pairs.
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/mesh_data.hpp"
#include "solver/beams/beam_scene.hpp"
#include "solver/io/selection.hpp"
#include "solver/linalg/linear_solver.hpp"
#include "solver/materials/material.hpp"
#include "solver/nonlinear/load_stepper.hpp"
#include "solver/terms/load_curve.hpp"

namespace stentsim::solver {

/// Where the (radial, circumferential, longitudinal) frame per cell comes from.
struct FrameSource {
  enum class Kind { none, cylindrical, file } kind = Kind::none;
  Vec3 origin = Vec3::Zero(), axis = Vec3::UnitZ();  // cylindrical
  std::filesystem::path file;                        // a VTU with one cell per body cell
  std::string radial = "Radial", circumferential = "Circumferential", longitudinal = "Longitudinal";
  /// file: cell arrays with the fiber direction of family 1, 2, ... of each cell's material
  /// (families given by angle); empty (`fibers: none`) = rebuild them from the frame and the angles.
  std::vector<std::string> fibers{"Fiber1", "Fiber2"};
};

struct BodyDesc {
  std::string name;
  /// A beam body (`beam:` in the scene, solver/beams/beam_scene.hpp) instead of a solid mesh.
  std::optional<beams::BeamBodyDesc> beam;
  MeshData mesh;
  std::string mesh_source;                  // file name or generator, for the summary
  std::string tag_array;                    // cell array with the material tag ("" = one material)
  std::map<int, Material> materials;        // by tag
  FrameSource frames;
};

// Conditions, quantities of interest and contact pairs are kinds, each in a
// file of its own that reads its scene entry into a spec (scene_kinds.hpp)
// and registered in one list per family (conditions/, qoi/, contact/ under
// solver/app); the scene holds the parsed specs.
class ConditionSpec;
class QoiSpec;
class ContactSpec;

struct SceneDesc {
  std::filesystem::path file;
  std::string description;
  std::vector<BodyDesc> bodies;
  std::map<std::string, LoadCurve> curves;
  std::string load_factor_curve;            // history.csv "load_factor" column
  std::vector<std::shared_ptr<const ConditionSpec>> conditions;
  StepperSettings stepping;
  NewtonSettings newton;
  LinearSolverSettings linear;
  int output_every = 1;                     // VTU every N steps (and at every stop)
  int checkpoint_every = 0;                 // checkpoint.bin every N steps (0: none); `solve --restart` resumes
  std::vector<std::shared_ptr<const QoiSpec>> qois;
  std::vector<std::shared_ptr<const ContactSpec>> contacts;
  /// What a checkpoint's state depends on besides the load curves (app/checkpoint.hpp):
  /// the canonical text of the `bodies`, `conditions` and `contact` sections, and the
  /// files the bodies name (meshes, beams, fiber frames).
  std::map<std::string, std::string> state_sections;
  std::vector<std::filesystem::path> state_files;

  const BodyDesc* body(const std::string& name) const;
};

/// Reads and validates a scene; meshes are read or generated.
SceneDesc read_scene(const std::filesystem::path& file);
/// The same from the text of a scene that lives (or will live) at `file`:
/// relative paths resolve against its folder and errors name it.
SceneDesc read_scene(const std::string& text, const std::filesystem::path& file);

}  // namespace stentsim::solver
