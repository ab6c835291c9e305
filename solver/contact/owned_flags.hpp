#pragma once
// Contact pairs evaluate only the items (beam elements, slave nodes) of their
// rank's fixed partition (SystemState::owns), so each rank's per-point flags
// are right for its own items only. Gathering them at commit gives every rank,
// and rank 0's checkpoint, all of them.
#include <Eigen/Core>

#include <vector>

#include "solver/assembly/parallel.hpp"
#include "solver/terms/term.hpp"

namespace stentsim::solver::contact {

/// `flags` holds `per_item` entries per item, item-major; entries of items other ranks own are replaced by theirs.
inline void gather_owned_flags(std::vector<char>& flags, std::size_t per_item, int rank, int ranks) {
  if (ranks <= 1) return;
  const std::size_t items = flags.size() / per_item;
  Eigen::VectorXd v = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(flags.size()));
  const SystemState owner{v, 0.0, 0.0, rank, ranks};
  for (std::size_t i = 0; i < items; ++i)
    if (owner.owns(i, items))
      for (std::size_t k = 0; k < per_item; ++k) v[static_cast<Eigen::Index>(i * per_item + k)] = flags[i * per_item + k];
  parallel::sum(v);
  for (std::size_t i = 0; i < flags.size(); ++i) flags[i] = v[static_cast<Eigen::Index>(i)] != 0.0;
}

}  // namespace stentsim::solver::contact
