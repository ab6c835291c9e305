#pragma once
// Pieces several scene kinds share (one implementation each):
// - the boundary faces of a solid body's cells that a selection picks, never empty;
// - a contact pair's `times: {label: time}` (summary entries at those times, each a stop).
#include <map>
#include <string>
#include <vector>

#include "common/config.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/io/scene_kinds.hpp"
#include "solver/io/selection.hpp"
#include "solver/terms/solid_body.hpp"

namespace stentsim::solver {

/// InputError "<scene>: <who>: the surface selection (...) selects no boundary face of body '<name>'" when empty.
std::vector<fem::Face> selected_boundary_faces(const SceneDesc& scene, const std::string& who, const SolidBody& body,
                                               const Selector& where);

/// Reads the optional `key: {label: time, ...}`; every time must lie inside solver.time and becomes a stop.
std::map<std::string, double> read_report_times(ConfigMap& c, const std::string& key, SceneReader& r);

}  // namespace stentsim::solver
