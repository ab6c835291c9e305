#include <fmt/format.h>

#include "solver/fem/face_orientation.hpp"
#include "solver/terms/element_failure.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "solver/terms/robin_springs.hpp"
#include "solver/terms/surface_kernel.hpp"

namespace stentsim::solver {
namespace {

template <class S>
void gather(const SolidBody& body, const fem::Face& f, const Eigen::VectorXd& u, typename SurfaceElement<S>::NodeMat& xr,
            typename SurfaceElement<S>::NodeMat& disp, std::array<GlobalDof, 3 * S::kNodes>& dofs) {
  for (int i = 0; i < S::kNodes; ++i) {
    const auto node = static_cast<std::size_t>(f.nodes[static_cast<std::size_t>(i)]);
    xr.col(i) = body.mesh().points[node];
    for (int a = 0; a < 3; ++a) dofs[static_cast<std::size_t>(3 * i + a)] = body.dof(node, a);
    disp.col(i) = u.segment<3>(body.dof(node, 0));
  }
}

}  // namespace

FollowerPressure::FollowerPressure(std::string name, const SolidBody& body, std::vector<fem::Face> faces, double magnitude,
                                   LoadCurve curve)
    : name_(std::move(name)), body_(body), faces_(std::move(faces)), magnitude_(magnitude), curve_(std::move(curve)) {
  outward_.reserve(faces_.size());
  const auto reference = [&](std::size_t node) -> Eigen::Vector3d { return body_.mesh().points[node]; };
  for (const auto& f : faces_) outward_.push_back(fem::face_side(body_.mesh(), f, reference) < 0.0);
}

std::string FollowerPressure::rejects(const SystemState& state) const {
  const auto current = [&](std::size_t node) -> Eigen::Vector3d { return body_.position(state.u, node); };
  std::size_t flipped = 0, first = 0;
  for (std::size_t e = 0; e < faces_.size(); ++e)
    if (outward_[e] && !(fem::face_side(body_.mesh(), faces_[e], current) < 0.0) && flipped++ == 0) first = e;
  if (flipped == 0) return {};
  const Vec3 at = body_.position(state.u, static_cast<std::size_t>(faces_[first].nodes[0]));
  return fmt::format("{} on body '{}': {} of {} loaded faces turned inside out or collapsed (they face their own cells), "
                     "the first of cell {} at ({:.4g}, {:.4g}, {:.4g}); the pressure is likely far beyond what the "
                     "body can carry, or the first step too large",
                     name_, body_.name(), flipped, faces_.size(), faces_[first].cell, at.x(), at.y(), at.z());
}

template <class S>
void FollowerPressure::add_face(const fem::Face& f, const SystemState& state, double p, Assembler& out, bool tangent) const {
  using K = SurfaceElement<S>;
  typename K::NodeMat xr, disp;
  std::array<GlobalDof, K::kDofs> dofs;
  gather<S>(body_, f, state.u, xr, disp, dofs);
  typename K::Vec r;
  typename K::Mat k;
  K::pressure(xr + disp, p, r, tangent ? &k : nullptr);
  if (!r.allFinite()) throw ElementFailure(fmt::format("{} on body '{}': face of cell {} not finite", name_, body_.name(), f.cell));
  if (tangent) out.add(dofs, r, k);
  else out.add(dofs, r, Eigen::MatrixXd());
}

void FollowerPressure::assemble(const SystemState& state, Assembler& out) {
  const double p = pressure(state.time);
  if (p == 0.0) return;
  const bool tangent = out.wants_tangent();
  for (std::size_t e = 0; e < faces_.size(); ++e) {
    if (!state.owns(e, faces_.size())) continue;
    const auto& f = faces_[e];
    switch (f.type) {
      case CellType::quad: add_face<fem::Quad4>(f, state, p, out, tangent); break;
      case CellType::triangle: add_face<fem::Tri3>(f, state, p, out, tangent); break;
      case CellType::quadratic_triangle: add_face<fem::Tri6>(f, state, p, out, tangent); break;
      default: break;
    }
  }
}

RobinSprings::RobinSprings(std::string name, const SolidBody& body, std::vector<fem::Face> faces, double stiffness)
    : name_(std::move(name)), body_(body), faces_(std::move(faces)), stiffness_(stiffness) {}

template <class S>
void RobinSprings::add_face(const fem::Face& f, const SystemState& state, Assembler& out) const {
  using K = SurfaceElement<S>;
  typename K::NodeMat xr, disp;
  std::array<GlobalDof, K::kDofs> dofs;
  gather<S>(body_, f, state.u, xr, disp, dofs);
  typename K::Vec r;
  typename K::Mat k;
  K::spring(xr, disp, stiffness_, r, k);
  out.add(dofs, r, k);
}

void RobinSprings::assemble(const SystemState& state, Assembler& out) {
  for (std::size_t e = 0; e < faces_.size(); ++e) {
    if (!state.owns(e, faces_.size())) continue;
    const auto& f = faces_[e];
    switch (f.type) {
      case CellType::quad: add_face<fem::Quad4>(f, state, out); break;
      case CellType::triangle: add_face<fem::Tri3>(f, state, out); break;
      case CellType::quadratic_triangle: add_face<fem::Tri6>(f, state, out); break;
      default: break;
    }
  }
}

}  // namespace stentsim::solver
