#include "solver/beams/rigid_joints.hpp"

#include "common/error.hpp"

#include <numeric>

namespace stentsim::solver::beams {

namespace {

int find_root(std::vector<int>& parent, int n) {
  while (parent[n] != n) n = parent[n] = parent[parent[n]];
  return n;
}

}  // namespace

JointMap make_joint_map(const BeamBodyDefinition& body, const std::vector<std::array<int, 2>>& joints,
                        const std::string& where, double position_tolerance) {
  const int nn = static_cast<int>(body.nodes.size());
  std::vector<int> parent(nn);
  std::iota(parent.begin(), parent.end(), 0);
  const std::vector<bool> end = beam_end_nodes(body);
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const auto [a, b] = joints[j];
    const std::string pair = "joint " + std::to_string(j) + " (nodes " + std::to_string(a) + ", " + std::to_string(b) + ")";
    if (a < 0 || b < 0 || a >= nn || b >= nn)
      throw InputError(where + ": " + pair + " refers to a node outside 0.." + std::to_string(nn - 1));
    if (a == b || !end[a] || !end[b])
      throw InputError(where + ": " + pair + " must join two different element end nodes");
    const double gap = (body.nodes[a].position - body.nodes[b].position).norm();
    if (gap > position_tolerance)
      throw InputError(where + ": " + pair + " joins nodes " + std::to_string(gap) +
                       " mm apart; a rigid joint needs equal reference positions");
    const int ra = find_root(parent, a), rb = find_root(parent, b);
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);  // the lowest node is the master
  }
  JointMap m;
  m.master.resize(nn);
  for (int n = 0; n < nn; ++n) m.master[n] = find_root(parent, n);
  return m;
}

std::vector<BeamNodeDofs> number_joined_beam_dofs(const BeamBodyDefinition& body, const JointMap& joints,
                                                  GlobalDof first, GlobalDof* next) {
  const std::vector<bool> end = beam_end_nodes(body);
  const bool hermite = body.interpolation == BeamInterpolation::hermite3;
  std::vector<BeamNodeDofs> dofs(body.nodes.size());
  GlobalDof k = first;
  // Masters have the lowest index of their group, so they are numbered first.
  for (std::size_t n = 0; n < dofs.size(); ++n) {
    const int m = joints.master.at(n);
    if (m != static_cast<int>(n)) {
      dofs[n].pos = dofs[m].pos;
      dofs[n].rot = dofs[m].rot;
    } else {
      if (end[n])
        for (int i = 0; i < 3; ++i) dofs[n].pos[i] = k++;
      if (end[n] || hermite)
        for (int i = 0; i < 3; ++i) dofs[n].rot[i] = k++;
    }
    if (end[n] && hermite)
      for (int i = 0; i < 3; ++i) dofs[n].tan[i] = k++;
  }
  if (next) *next = k;
  return dofs;
}

void require_master_node(const JointMap& joints, int node, const std::string& where) {
  if (joints.is_slave(node))
    throw InputError(where + ": node " + std::to_string(node) + " is the slave of a rigid joint; put the condition on its master node " +
                     std::to_string(joints.master[node]));
}

}  // namespace stentsim::solver::beams
