#pragma once
// The interior Voronoi diagram of a surface's vertices, as VMTK uses it for
// centerlines (Antiga et al., "Robust and objective decomposition and mapping
// of bifurcating vessels", IEEE TMI 23(6), 2004; Antiga's thesis, 2002): the
// circumcentres of the Delaunay tetrahedra approximate the medial axis and
// their circumradii the maximum inscribed sphere radius. Nodes are the
// circumcentres of the tetrahedra whose centre lies on the inner side of all
// four vertices' (outward) normals; edges join tetrahedra sharing a face.
#include <Eigen/Core>

#include <vector>

#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::segmentation {

struct MedialGraph {
  std::vector<Eigen::Vector3d> centers;
  std::vector<double> radius;
  std::vector<std::vector<int>> neighbours;
};

/// Requires consistently outward-oriented triangles.
MedialGraph interior_voronoi_graph(const TriSurface& surface);

/// Area-weighted outward vertex normals (unit; zero for unused vertices).
std::vector<Eigen::Vector3d> vertex_normals(const TriSurface& surface);

}  // namespace stentsim::segmentation
