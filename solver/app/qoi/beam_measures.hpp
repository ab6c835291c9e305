#pragma once
// Measures of a beam body that several QoIs report.
#include <Eigen/Core>

#include <algorithm>

#include "solver/beams/beam_term.hpp"

namespace stentsim::solver {

/// Largest bending moment ‖M_b‖ over every Gauss point of the body at u [N mm]
/// (plastic sections: the return from the committed history).
inline double max_bending_moment(const beams::BeamTerm& beam, const Eigen::VectorXd& u) {
  double mb = 0.0;
  for (std::size_t e = 0; e < beam.body().elements.size(); ++e)
    for (const auto& st : beam.section_states(u, e)) mb = std::max(mb, st.M.tail<2>().norm());
  return mb;
}

}  // namespace stentsim::solver
