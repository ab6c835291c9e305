#include "solver/assembly/model.hpp"

#include "solver/assembly/parallel.hpp"
#include "solver/terms/element_failure.hpp"

namespace stentsim::solver {

void Model::assemble(const Eigen::VectorXd& u, double time, double dt, const Eigen::VectorXd& prescribed,
                     GlobalSystem& system, bool with_tangent) {
  system.begin(prescribed, with_tangent);
  system.set_parallel(rank, ranks);
  SystemState state{u, time, dt, rank, ranks};
  // A failing element on one rank must fail the assembly on every rank.
  std::string failure;
  try {
    for (auto& t : terms) t->assemble(state, system);
  } catch (const ElementFailure& e) {
    failure = e.what();
  }
  if (ranks > 1) {
    const std::string first = parallel::first_message(!failure.empty(), failure);
    if (!first.empty()) throw ElementFailure(first);
  } else if (!failure.empty()) {
    throw ElementFailure(failure);
  }
  system.finish();
}

void Model::begin_step(const Eigen::VectorXd& u, double time, double dt) {
  const SystemState state{u, time, dt, rank, ranks};
  std::string failure;
  try {
    for (auto& t : terms) t->begin_step(state);
  } catch (const ElementFailure& e) {
    failure = e.what();
  }
  if (ranks > 1) failure = parallel::first_message(!failure.empty(), failure);
  if (!failure.empty()) throw ElementFailure(failure);
}

std::string Model::rejects(const Eigen::VectorXd& u, double time, double dt) const {
  // Every rank holds the same u and every term judges all of its own parts, so
  // the ranks agree without a message.
  const SystemState state{u, time, dt, rank, ranks};
  for (const auto& t : terms)
    if (std::string why = t->rejects(state); !why.empty()) return why;
  return {};
}

int Model::accepted_changes() const {
  int n = 0;
  for (const auto& t : terms) n += t->accepted_changes();
  if (ranks == 1) return n;
  Eigen::VectorXd v = Eigen::VectorXd::Constant(1, n);
  parallel::sum(v);  // collective: every rank calls it after every accept
  return static_cast<int>(v[0]);
}

Eigen::MatrixXd Model::rigid_body_modes(const std::vector<std::pair<GlobalDof, Vec3>>& nodes) const {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(dofs.size(), 6);
  for (const auto& [first, x] : nodes) {
    for (int a = 0; a < 3; ++a) m(first + a, a) = 1.0;
    // rotations: e_k x X
    m(first + 1, 3) = -x.z(), m(first + 2, 3) = x.y();
    m(first + 0, 4) = x.z(), m(first + 2, 4) = -x.x();
    m(first + 0, 5) = -x.y(), m(first + 1, 5) = x.x();
  }
  return m;
}

namespace {
std::string term_prefix(std::size_t i, const Term& t) { return "term/" + std::to_string(i) + ":" + t.name() + "/"; }
}  // namespace

void Model::save_history(HistoryArchive& out) const {
  for (std::size_t i = 0; i < terms.size(); ++i) terms[i]->save_history(out, term_prefix(i, *terms[i]));
}

void Model::load_history(const HistoryArchive& in) {
  for (std::size_t i = 0; i < terms.size(); ++i) terms[i]->load_history(in, term_prefix(i, *terms[i]));
}

}  // namespace stentsim::solver
