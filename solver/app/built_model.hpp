#pragma once
// A scene turned into a model (build_model.cpp): the Model the nonlinear
// solver drives, and the handles that conditions, QoIs, contact pairs and the
// output need to find their bodies and terms again by name.
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "solver/assembly/model.hpp"
#include "solver/beams/beam_scene.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/radial_release.hpp"
#include "solver/io/scene.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "solver/terms/solid_body.hpp"

namespace stentsim::solver {

class RunObserver;

struct BuiltModel {
  Model model;
  std::map<std::string, SolidBody*> bodies;                      // solid bodies by name
  std::map<std::string, beams::BeamTerm*> beams;                 // beam bodies by name
  std::map<std::string, const beams::BeamBodyDesc*> beam_desc;
  std::vector<std::pair<std::string, FollowerPressure*>> pressures;          // by condition name
  std::map<std::string, beams::RadialDisplacementTerm*> radial;              // radial_displacement conditions by name
  std::vector<std::pair<GlobalDof, GlobalDof>> direction_multipliers;        // (first, count) per direction condition
  /// Contact pairs' outputs (history columns, VTU arrays, summary entries), in scene order.
  std::vector<std::unique_ptr<RunObserver>> observers;
  /// Beam bodies whose strut overlap is checked (contact pairs add the check once per beam).
  std::set<std::string> overlap_checked_beams;
  /// Solid bodies whose contact surface is checked for self-intersection (once per body).
  std::set<std::string> self_intersection_checked_solids;
  /// Lines for summary.yaml's notes (materials, laws, penalties).
  std::vector<std::string> notes;
  /// Node first DOF -> condition name, for conflicting solid Dirichlet conditions.
  std::map<GlobalDof, std::string> framed_nodes, fixed_nodes;

  BuiltModel();
  ~BuiltModel();
  SolidBody& solid(const std::string& name) const { return *bodies.at(name); }
  beams::BeamTerm& beam(const std::string& name) const { return *beams.at(name); }
};

/// Builds the model of a scene: bodies, conditions, contact pairs (only what the scene names).
std::unique_ptr<BuiltModel> build_model(const SceneDesc& scene);

/// The 6 rigid-body modes of the solid nodes for SA-AMG; InputError naming the
/// scene's solver.linear.type when the model has DOFs they cannot describe.
Eigen::MatrixXd amg_near_null_space(const SceneDesc& scene, const BuiltModel& b);
/// The solid nodes' reference coordinates, row d/3 for the node whose first DOF is d
/// (call after amg_near_null_space, which checks that every unknown is a solid displacement).
Eigen::MatrixXd amg_node_coordinates(const BuiltModel& b);

/// gmres_amg_block's AMG block: the largest solid body's unknowns [begin, end)
/// (a solid body's DOFs are contiguous, 3 per node), with that block's
/// rigid-body modes and node coordinates.
struct AmgBlock {
  std::string body;
  GlobalDof begin = 0, end = 0;
  Eigen::MatrixXd modes, coordinates;
};
/// InputError naming the scene's solver.linear.type when the scene has no
/// solid body or nothing outside it (then gmres_amg is the solver to use).
AmgBlock amg_block(const SceneDesc& scene, const BuiltModel& b);

}  // namespace stentsim::solver
