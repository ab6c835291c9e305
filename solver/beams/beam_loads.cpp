#include "solver/beams/beam_loads.hpp"

#include <numeric>
#include <utility>

namespace stentsim::solver::beams {

NodalLoadTerm::NodalLoadTerm(std::string name, std::array<GlobalDof, 3> dofs, Eigen::Vector3d value, LoadScale scale)
    : name_(std::move(name)), dofs_(dofs), value_(std::move(value)), scale_(std::move(scale)) {}

void NodalLoadTerm::assemble(const SystemState& state, Assembler& out) {
  if (state.rank != 0) return;  // added once
  const double s = scale_ ? scale_(state.time) : 1.0;
  const Eigen::Vector3d R = -s * value_;
  out.add(dofs_, R, Eigen::Matrix3d::Zero());
}

BeamLineLoadTerm::BeamLineLoadTerm(std::string name, const BeamTerm& beam, Eigen::Vector3d force_per_length,
                                   LoadScale scale, std::vector<std::size_t> elements)
    : name_(std::move(name)), beam_(beam), f_(std::move(force_per_length)), scale_(std::move(scale)),
      elements_(std::move(elements)) {
  if (elements_.empty()) {
    elements_.resize(beam_.body().elements.size());
    std::iota(elements_.begin(), elements_.end(), std::size_t{0});
  }
}

void BeamLineLoadTerm::assemble(const SystemState& state, Assembler& out) {
  const double s = scale_ ? scale_(state.time) : 1.0;
  for (std::size_t i = 0; i < elements_.size(); ++i) {
    if (!state.owns(i, elements_.size())) continue;
    const std::size_t e = elements_[i];
    const ElementReference& ref = beam_.reference(e);
    const int nc = ref.centerline_vectors();
    const std::vector<GlobalDof> all = beam_.element_dofs(e);
    const std::vector<GlobalDof> d(all.begin(), all.begin() + 3 * nc);  // centerline DOFs come first
    Eigen::VectorXd R = Eigen::VectorXd::Zero(3 * nc);
    for (const ShapePoint& p : ref.points)
      for (int k = 0; k < nc; ++k) R.segment<3>(3 * k) -= s * p.weight_ds * p.B[k] * f_;
    out.add(d, R, Eigen::MatrixXd::Zero(3 * nc, 3 * nc));
  }
}

}  // namespace stentsim::solver::beams
