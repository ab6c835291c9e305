#pragma once
// The analytic references of the error study, evaluated from each run's own
// effective input (so a knob changing E, nu or the pressure keeps the
// reference consistent):
// - tube_plane_strain: inner radius of the plane-strain neo-Hooke tube under
//   its follower pressure (references/tube_reference.hpp, shooting + Newton);
// - beam_rollup: a straight cantilever under an end moment M bends into an arc
//   of curvature kappa = |M| / (E I): tip = start + (sin(kappa L) e1 +
//   (1 - cos(kappa L)) e2) / kappa, e2 = m x e1, rotation angle kappa L.
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "workflows/study/study_config.hpp"

namespace stentsim::study {

/// Reference value of `study.qoi` for the run whose input is `input`
/// (tube_plane_strain, beam_rollup, value). Throws InputError naming the study
/// file and the missing or unusable key.
std::vector<double> analytic_reference(const StudyConfig& study, const YAML::Node& input);

}  // namespace stentsim::study
