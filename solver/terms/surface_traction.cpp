#include "solver/terms/surface_traction.hpp"

#include "solver/terms/surface_kernel.hpp"

namespace stentsim::solver {

SurfaceTraction::SurfaceTraction(std::string name, const SolidBody& body, std::vector<fem::Face> faces, const Vec3& traction,
                                 LoadCurve curve)
    : name_(std::move(name)), body_(body), faces_(std::move(faces)), traction_(traction), curve_(std::move(curve)) {}

template <class S>
void SurfaceTraction::add_face(const fem::Face& f, const Vec3& t, Assembler& out) const {
  constexpr int n = S::kNodes;
  Eigen::Matrix<double, 3, n> xr;
  std::array<GlobalDof, 3 * n> dofs;
  for (int i = 0; i < n; ++i) {
    const auto node = static_cast<std::size_t>(f.nodes[static_cast<std::size_t>(i)]);
    xr.col(i) = body_.mesh().points[node];
    for (int a = 0; a < 3; ++a) dofs[static_cast<std::size_t>(3 * i + a)] = body_.dof(node, a);
  }
  Eigen::Matrix<double, 3 * n, 1> r = Eigen::Matrix<double, 3 * n, 1>::Zero();
  for (int q = 0; q < S::kRule.kPoints; ++q) {
    const auto sv = S::eval(S::kRule.points[q]);
    const double da = (xr * sv.dn.col(0)).cross(xr * sv.dn.col(1)).norm() * S::kRule.weights[q];
    for (int i = 0; i < n; ++i) r.template segment<3>(3 * i) -= da * sv.n(i) * t;
  }
  out.add(dofs, r, Eigen::Matrix<double, 3 * n, 3 * n>::Zero());
}

void SurfaceTraction::assemble(const SystemState& state, Assembler& out) {
  const Vec3 t = traction_ * curve_(state.time);
  for (std::size_t e = 0; e < faces_.size(); ++e) {
    if (!state.owns(e, faces_.size())) continue;
    const auto& f = faces_[e];
    switch (f.type) {
      case CellType::quad: add_face<fem::Quad4>(f, t, out); break;
      case CellType::triangle: add_face<fem::Tri3>(f, t, out); break;
      case CellType::quadratic_triangle: add_face<fem::Tri6>(f, t, out); break;
      default: break;
    }
  }
}

}  // namespace stentsim::solver
