#pragma once
// The scene file (YAML): bodies (mesh + material per cell tag + fiber
// frames), load curves, conditions (follower pressure, Robin springs,
// Dirichlet on node sets in global axes or "radial only"), solver settings,
// outputs and quantities of interest. read_scene validates everything with
// errors naming file:line:key; examples/tube_inflation.yaml shows every part.
#include <filesystem>
#include <map>
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

struct ConditionDesc {
  // pressure, springs, dirichlet: solid bodies. clamp, point_force,
  // point_moment, direction, radial_displacement, fix_cylindrical, release:
  // beam bodies (node by beams::BeamNodeSelector).
  //   radial_displacement: (r − X)·e_r = value·curve(t) about `axis` (beams/radial_release.hpp)
  //   fix_cylindrical: zero displacement components (0 radial, 1 circumferential,
  //     2 axial) in the node's reference cylindrical frame about `axis`
  //   release: from time `release_at` on, the radial_displacement condition
  //     `release_from` becomes point forces equal to its last reactions × curve(t)
  enum class Type { pressure, springs, dirichlet, clamp, point_force, point_moment, direction, radial_displacement,
                    fix_cylindrical, release } type = Type::pressure;
  std::string name, body, curve;            // curve "" = constant 1
  Selector where;
  double value = 0.0;                       // pressure (MPa), stiffness (N/mm^3) or displacement (mm)
  std::vector<int> components;              // dirichlet: 0,1,2 (global axes)
  bool radial_only = false;                 // dirichlet: fix the circumferential and axial components
  Vec3 axis_origin = Vec3::Zero(), axis = Vec3::UnitZ();
  // beam conditions
  beams::BeamNodeSelector node;
  bool clamp_position = true, clamp_rotation = true, clamp_tangent = false;
  Vec3 vector = Vec3::Zero();               // point_force (N), point_moment (N mm), direction
  bool direction_from_file = false;         // direction: the stent file's fixation directions
  std::string release_from;                 // release: the radial_displacement condition
  double release_at = 0.0;                  // release: time (a stop)
};

struct QoiDesc {
  std::string name;
  // tip_position (vector, mm) and tip_rotation_angle (rad, accumulated over steps): beam bodies.
  // ring_expansion (beam bodies): mean diameter 2·mean(‖(r − o)⊥axis‖) of the
  // selected nodes at `time` (D_max) and at the end (D_end), recoil_percent =
  // 100 (D_max − D_end)/D_max, and the largest ‖M_b‖ over all Gauss points at
  // both times (max_bending_moment_peak, _end); summary keys without prefix.
  enum class Type { mean_radius, max_displacement, tip_position, tip_rotation_angle, ring_expansion } type = Type::mean_radius;
  std::string body;
  Selector where;
  beams::BeamNodeSelector node;
  Vec3 axis_origin = Vec3::Zero(), axis = Vec3::UnitZ();
  double time = 0.0;                        // evaluated at the output step at this time
};

struct SceneDesc {
  std::filesystem::path file;
  std::string description;
  std::vector<BodyDesc> bodies;
  std::map<std::string, LoadCurve> curves;
  std::string load_factor_curve;            // history.csv "load_factor" column
  std::vector<ConditionDesc> conditions;
  StepperSettings stepping;
  NewtonSettings newton;
  LinearSolverSettings linear;
  int output_every = 1;                     // VTU every N steps (and at every stop)
  int checkpoint_every = 0;                 // checkpoint.bin every N steps (0: none); `solve --restart` resumes
  std::vector<QoiDesc> qois;
};

/// Reads and validates a scene; meshes are read or generated.
SceneDesc read_scene(const std::filesystem::path& file);

}  // namespace stentsim::solver
