#pragma once
// The analytic references of the error study, evaluated from each run's own
// effective input (so a knob changing E, nu or the pressure keeps the
// reference consistent):
// - tube_plane_strain: inner radius of the plane-strain neo-Hooke tube under
//   its follower pressure (references/tube_reference.hpp, shooting + Newton);
// - beam_rollup: a straight cantilever under an end moment M bends into an arc
//   of curvature kappa = |M| / (E I): tip = start + (sin(kappa L) e1 +
//   (1 - cos(kappa L)) e2) / kappa, e2 = m x e1, rotation angle kappa L
//   (elastic beams only);
// - beam_plastic_rollup: the same cantilever with the elasto-plastic section
//   law of App. C (`material: stent` or `plastic:`, circular section): the
//   uniform moment M(t) (load curve, loading and unloading without reversal)
//   gives kappa = kappa(M; M_max) (references/plastic_moment_curvature.hpp);
// - beam_shooting: a generated arc or line clamped at its first node under a
//   dead point_force at its last (the 45 deg bend): the Simo-Reissner rod
//   solved by shooting (references/rod_shooting.hpp), tip position or tip
//   rotation angle; each distinct problem is solved once per process.
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "workflows/study/study_config.hpp"

namespace stentsim::study {

/// Reference value of `study.qoi` for the run whose input is `input`
/// (tube_plane_strain, beam_rollup, beam_plastic_rollup, beam_shooting,
/// value). Throws InputError naming the study file and the missing or
/// unusable key (or the load case the reference does not cover).
std::vector<double> analytic_reference(const StudyConfig& study, const YAML::Node& input);

}  // namespace stentsim::study
