#pragma once
// The QoI kinds, one factory per file; registry.cpp lists them.
#include "solver/io/scene_kinds.hpp"

namespace stentsim::solver {

QoiKind mean_radius_qoi();
QoiKind max_displacement_qoi();
QoiKind tip_position_qoi();
QoiKind tip_rotation_angle_qoi();
QoiKind ring_expansion_qoi();
QoiKind stent_expansion_qoi();
QoiKind balloon_profile_qoi();
QoiKind layer_stresses_qoi();
QoiKind malapposition_qoi();
QoiKind lumen_area_qoi();

}  // namespace stentsim::solver
