#pragma once
// Global DOF numbering: each body or term that owns DOFs (solid nodes: 3 per
// node; beam nodes: as the beam term needs) asks for a contiguous range.
#include <string>
#include <vector>

#include "solver/terms/term.hpp"

namespace stentsim::solver {

class DofMap {
 public:
  /// Reserves `count` DOFs for `owner`; returns the first.
  GlobalDof allocate(const std::string& owner, GlobalDof count) {
    const GlobalDof first = size_;
    ranges_.push_back({owner, first, count});
    size_ += count;
    return first;
  }
  GlobalDof size() const { return size_; }
  /// Which owner a DOF belongs to (for messages).
  std::string owner_of(GlobalDof dof) const {
    for (const auto& r : ranges_)
      if (dof >= r.first && dof < r.first + r.count) return r.owner;
    return "?";
  }
  struct Range {
    std::string owner;
    GlobalDof first, count;
  };
  const std::vector<Range>& ranges() const { return ranges_; }

 private:
  std::vector<Range> ranges_;
  GlobalDof size_ = 0;
};

}  // namespace stentsim::solver
