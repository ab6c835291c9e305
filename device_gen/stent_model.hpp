#pragma once
// The stent as beams: generated straight on the crimped cylinder (unrolled:
// circumferential arc u = R*phi, axial z), then warped onto the device axis
// (z -> arc length sigma, rotation-minimizing frame; DESIGN.md §5). Each strut
// and connector ("member") owns its nodes (DESIGN.md §8): 2*e+1 nodes for e
// Hermite elements, the end nodes of elements (9 DOFs: position, rotation,
// tangent) at even local indices, the middle nodes (3 rotational DOFs) at odd.
// Members meeting at a crown or a connector end are coupled by rigid joints,
// written as node pairs.
#include <Eigen/Core>

#include <array>
#include <vector>

#include "device_gen/device_axis.hpp"
#include "device_gen/stent_design.hpp"

namespace stentsim::device_gen {

struct StentModel {
  enum NodeKind { kEndNode = 0, kMiddleNode = 1 };
  enum MemberKind { kStrut = 0, kConnector = 1 };

  struct Element {
    std::array<int, 3> nodes;  // end, end, middle (VTK quadratic edge order)
    int member;
  };
  struct Member {
    MemberKind kind;
    int ring;            // the ring of a strut; for a connector the gap (between ring and ring+1)
    int first_element, elements;
    double straight_length;  // on the crimped cylinder before warping
  };
  struct Fixation {
    int node;
    Eigen::Vector3d direction;  // radial (free direction) or axial (fixed direction)
    bool axial;                 // false: moves only along `direction`; true: fixed along `direction`
  };

  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Matrix3d> triads;  // columns: e1 along the beam, e2 radial outward, e3 = e1 x e2
  std::vector<int> node_kind;
  std::vector<Eigen::Vector2d> unrolled;  // (phi, z) of each node on the straight cylinder
  std::vector<Element> elements;
  std::vector<Member> members;
  std::vector<std::array<int, 2>> joints;
  std::vector<Fixation> fixations;
  double length = 0;       // axial length of the straight stent
  double axis_start = 0;   // sigma of the stent's proximal end on the device axis

  /// Nodal DOFs before joint coupling: 9 per end node, 3 per middle node.
  int nodal_dofs() const;
};

/// Generates the stent of `design` centred on the axis midpoint and warps it
/// onto `axis`. One axial fixation is added when the axis is straight (paper 2.2).
/// Throws InputError when the stent is longer than the axis.
StentModel build_stent(const StentDesign& design, const DeviceAxis& axis);

}  // namespace stentsim::device_gen
