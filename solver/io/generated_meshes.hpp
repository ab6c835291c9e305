#pragma once
// Small structured meshes for scenes that generate their own geometry (the
// tube-inflation example) and for tests: boxes and ring sectors of hex8, the
// conforming 6-tet (Kuhn) split of a structured hex mesh, tet4 -> tet10.
#include "common/mesh_data.hpp"

namespace stentsim::solver {

/// nx x ny x nz hex8 box [0,lx] x [0,ly] x [0,lz].
MeshData box_hex8(int nx, int ny, int nz, double lx, double ly, double lz);

/// Ring sector about the z axis: radius ri..ro (nr elements, spacing uniform),
/// angle 0..angle_rad (nt elements), z in 0..height (nz elements).
/// angle_rad = 2 pi closes the ring (shared seam nodes). Point array
/// "ReferenceRadius" is added for convenience.
MeshData ring_sector_hex8(double ri, double ro, double angle_rad, double height, int nr, int nt, int nz);

/// Every hex8 into 6 tet4 around its 0-6 diagonal (conforming on structured meshes).
MeshData hex8_to_tet4(const MeshData& hex);

/// tet4 -> tet10 with shared straight-edge midpoints. Point arrays are dropped.
MeshData tet4_to_tet10(const MeshData& tet);

/// tet4 -> tet10 of a mesh of a ring about the z axis with each midside node
/// at the edge's midpoint in (r, theta, z): the quadratic elements then follow
/// the cylinders r = const exactly at their nodes (curved, isoparametric
/// geometry), so the inner and outer faces of a ring sector are not chords.
MeshData tet4_to_tet10_cylindrical(const MeshData& tet);

}  // namespace stentsim::solver
