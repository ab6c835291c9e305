#pragma once
// Spatial search for contact: a uniform grid of bins over the faces' current
// bounding boxes, each box inflated by the search margin. Built once per load
// step (and again when a point moved more than half the margin since), it
// answers "which faces may lie within the margin of this box" in O(1) per bin.
#include <Eigen/Core>

#include <vector>

#include "solver/contact/contact_surface.hpp"

namespace stentsim::solver::contact {

class FaceSearch {
 public:
  void build(const ContactSurface& surface, double margin);
  /// Faces whose inflated box overlaps the box [lo, hi] (sorted, unique).
  void query(const Vec3& lo, const Vec3& hi, std::vector<int>& out) const;
  double margin() const { return margin_; }

 private:
  Eigen::Array3i cell_of(const Vec3& x) const;
  double margin_ = 0.0, h_ = 1.0;
  Vec3 origin_ = Vec3::Zero();
  Eigen::Array3i dims_{1, 1, 1};
  std::vector<Eigen::AlignedBox3d> boxes_;
  std::vector<int> start_, items_;  // CSR: faces of bin b are items_[start_[b] .. start_[b+1])
};

}  // namespace stentsim::solver::contact
