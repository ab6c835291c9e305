#pragma once
// The case's solve stage (DESIGN.md §1, §3, §5): the earlier stages'
// artifacts and the case's `simulation` section become one plain solver
// scene, solve/scene.yaml, which the stage runs in-process (or, with
// simulation.ranks > 1, as an MPI child process) and which a user re-runs by
// hand with `stentsim solve solve/scene.yaml`. The case adds no physics the
// scene format cannot express (DESIGN.md §8).
#include <filesystem>
#include <string>

#include "pipeline/stage.hpp"
#include "workflows/case_config.hpp"

namespace stentsim::workflows {

/// DESIGN.md §8 (paper 2.5): the artery's contact faces should be no smaller
/// than the strut diameter. Empty when they are; else the warning (also logged)
/// naming the file, how many endothelium faces are smaller and the shortest edge.
std::string contact_face_size_warning(const std::filesystem::path& artery_vtu, double strut_diameter);

/// The scene text, with paths relative to the work folder's solve/ (where it is written).
std::string solve_scene_text(const CaseConfig& c);

/// The stage: inputs balloon/balloon.vtu, stent/stent.vtu (with an artery also mesh/artery.vtu,
/// fibers/fibers.vtu); outputs solve/scene.yaml,
/// solve/results.pvd, solve/results/, solve/history.csv (and solve/summary.yaml).
pipeline::Stage solve_stage(const CaseConfig& c);

}  // namespace stentsim::workflows
