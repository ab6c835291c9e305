#pragma once
// Which side of a boundary face its volume cell lies on. A loaded surface
// whose faces turned to the other side of their cells is inside out: under a
// follower pressure the lumen of a tube can pass through the axis and settle
// where the flipped faces push inwards and their area, and so the pressure's
// force, has shrunk to nothing — an equilibrium of the discrete equations with
// J > 0 at every quadrature point that no physical state matches.
#include <Eigen/Core>

#include <functional>

#include "common/mesh_data.hpp"
#include "solver/fem/boundary_faces.hpp"

namespace stentsim::solver::fem {

/// n . (c_cell - c_face) for the face's corner-node normal n (right-hand rule,
/// outward in the reference) and the centroids of the cell's and the face's
/// nodes: negative while the face looks away from its cell, positive once it
/// is turned inside out, zero when it has collapsed. `position(node)` gives a
/// node's current (or reference) position.
double face_side(const MeshData& mesh, const Face& face, const std::function<Eigen::Vector3d(std::size_t)>& position);

}  // namespace stentsim::solver::fem
