#pragma once
// A triangulated surface as the segmentation stage works on it: points and
// index triples. Light (Eigen only); conversions to and from MeshData, which
// is what the stages exchange through files.
#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

#include "common/mesh_data.hpp"

namespace stentsim::segmentation {

struct TriSurface {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;

  std::size_t num_triangles() const { return triangles.size(); }
};

/// The triangles of `mesh` (quads split in two; lines and vertices ignored).
/// Throws InputError when the mesh holds cells of any other kind.
TriSurface surface_from_mesh(const MeshData& mesh, const std::string& what);
/// MeshData with triangle cells (points and connectivity only).
MeshData mesh_from_surface(const TriSurface& s);

/// An open boundary of the surface: a closed loop of boundary edges.
struct BoundaryLoop {
  std::vector<int> vertices;  // in order along the loop
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // length-weighted
  double perimeter = 0;
  double mean_radius = 0;  // mean distance of the loop vertices from the centroid
};

/// All boundary loops (edges used by exactly one triangle), largest perimeter
/// first. Requires a manifold surface; non-manifold vertices on the boundary
/// are walked as they come.
std::vector<BoundaryLoop> boundary_loops(const TriSurface& s);

/// The surface with each boundary loop closed by a fan around its centroid
/// (used to decide inside/outside for an open tube).
TriSurface capped(const TriSurface& s, const std::vector<BoundaryLoop>& loops);

/// Signed enclosed volume (positive for outward normals) of a closed surface.
double signed_volume(const TriSurface& s);
double surface_area(const TriSurface& s);
/// Axis-aligned bounding box diagonal length.
double bounding_box_diagonal(const TriSurface& s);

}  // namespace stentsim::segmentation
