#pragma once
// Bounds of a contact face's current points, for culling projections before
// their local Newton: every point x(ξ) of a face with ξ inside it lies in the
// convex hull of its Bézier control points — the corners of quad4 and tri3,
// and for tri6 the corners with 2 m − (a + b)/2 per edge (a, b its ends, m its
// mid-side node) — so the box of those points holds the whole face.
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>

#include "solver/contact/contact_surface.hpp"

namespace stentsim::solver::contact {

inline Eigen::AlignedBox3d face_box(const ContactSurface& s, const SurfaceFace& f) {
  Eigen::AlignedBox3d box;
  const int corners = f.kind == FaceKind::quad4 ? 4 : 3;
  for (int k = 0; k < corners; ++k) box.extend(s.x(f.node[k]));
  if (f.kind == FaceKind::tri6)
    for (int e = 0; e < 3; ++e)  // edge e: corners e, (e + 1) % 3, mid-side node 3 + e (VTK order)
      box.extend(2.0 * s.x(f.node[3 + e]) - 0.5 * (s.x(f.node[e]) + s.x(f.node[(e + 1) % 3])));
  // Widened a little for the projections' inside tolerance and round-off.
  const double pad = 1e-6 * box.diagonal().norm() + 1e-12;
  box.min().array() -= pad;
  box.max().array() += pad;
  return box;
}

inline std::vector<Eigen::AlignedBox3d> face_boxes(const ContactSurface& s) {
  std::vector<Eigen::AlignedBox3d> out;
  out.reserve(s.faces().size());
  for (const SurfaceFace& f : s.faces()) out.push_back(face_box(s, f));
  return out;
}

/// Whether the segment p + α d, α in [lo, hi], meets `box` (slab test).
inline bool segment_meets_box(const Vec3& p, const Vec3& d, double lo, double hi, const Eigen::AlignedBox3d& box) {
  for (int c = 0; c < 3; ++c) {
    if (d[c] == 0.0) {
      if (p[c] < box.min()[c] || p[c] > box.max()[c]) return false;
      continue;
    }
    double t0 = (box.min()[c] - p[c]) / d[c], t1 = (box.max()[c] - p[c]) / d[c];
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0), hi = std::min(hi, t1);
    if (lo > hi) return false;
  }
  return true;
}

}  // namespace stentsim::solver::contact
