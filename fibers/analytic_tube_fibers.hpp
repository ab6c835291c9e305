#pragma once
// Fiber fields of a straight tube along +z in closed form (paper Section 4.2,
// Fig. 1b): per element the local frame (radial, circumferential,
// longitudinal) at its centroid and two fiber families at ±phi from the
// circumferential direction in the circumferential–longitudinal plane.
// Used by the generic-artery scene and as the reference the harmonic-lifting
// fibers are tested against.
#include <map>
#include <string>

#include "common/mesh_data.hpp"
#include "common/summary.hpp"

namespace stentsim::fibers {

/// Fiber angle per layer (rad, from circumferential), keyed by tags::Layer.
using LayerAngles = std::map<int, double>;

/// The fiber field on the volume cells of `mesh` (faces are skipped): a copy
/// of the volume mesh with cell arrays Radial, Circumferential, Longitudinal,
/// Fiber1, Fiber2 (unit vectors), Layer and Transmural (cell and point data,
/// ln(r/r_i)/ln(r_o/r_i), the harmonic transmural coordinate). Throws InputError for a layer
/// without an angle.
MeshData tube_fibers(const MeshData& mesh, const LayerAngles& angles);

void write_tube_fibers(const std::string& artery_vtu, const LayerAngles& angles, const std::string& fibers_vtu,
                       Summary& summary);

}  // namespace stentsim::fibers
