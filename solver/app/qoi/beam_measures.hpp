#pragma once
// Measures of a beam body that several QoIs report.
#include <Eigen/Core>

#include <algorithm>
#include <map>
#include <set>
#include <vector>

#include "solver/beams/beam_scene.hpp"
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

/// The nodes of each ring of a stent file's beam body, rings in order (the end nodes of the
/// ring's strut elements: crowns and the nodes between a strut's elements); empty when the
/// body has no ring membership (not a stent file).
inline std::vector<std::vector<int>> stent_ring_nodes(const beams::BeamBodyDesc& desc) {
  if (desc.element_ring.size() != desc.body.elements.size()) return {};
  std::map<int, std::set<int>> rings;
  for (std::size_t e = 0; e < desc.body.elements.size(); ++e)
    if (desc.element_ring[e] >= 0) {
      const auto& el = desc.body.elements[e];
      rings[desc.element_ring[e]].insert(el.a), rings[desc.element_ring[e]].insert(el.b);
    }
  std::vector<std::vector<int>> out;
  for (auto& [k, nodes] : rings) out.emplace_back(nodes.begin(), nodes.end());
  return out;
}

}  // namespace stentsim::solver
