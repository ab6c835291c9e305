#pragma once
// A tagged wall mesh of a straight or bent tube (tet4 or tet10 from the
// solver's structured generators): Layer (inner half media, outer half
// adventitia) and boundary faces with FaceGroup, as artery.vtu carries them.
// For the fiber stage's tests and benchmark, independent of the meshing stage.
#include "common/mesh_data.hpp"

namespace stentsim::fibers {

struct TaggedTubeSpec {
  double inner_radius = 0.8, outer_radius = 1.4, length = 3.0;  // mm
  int elements_radial = 4, elements_around = 64, elements_along = 8;
  bool quadratic = false;  // tet10 instead of tet4
  /// Radius of curvature of the axis (mm; 0: straight along +z). The axis bends
  /// in the x-z plane about (bend, 0, 0), starting at the origin along +z.
  double bend_radius = 0;
};

MeshData tagged_tube(const TaggedTubeSpec& s);

/// The tube's axis as a polyline from z = -extend to length + extend (before bending).
MeshData tagged_tube_axis(const TaggedTubeSpec& s, double extend = 0.5, int segments = 40);

}  // namespace stentsim::fibers
