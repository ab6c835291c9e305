// The plastic history a BeamTerm commits must be the one of the converged
// state (issue 9, risk from part 2): Newton re-assembles after accepting its
// last iterate, and BeamTerm::commit refuses a commit whose last assemble was
// at another state.
// - protocol: trial → accept → commit without an assemble throws;
// - Newton (solver core) with a loose tolerance, so that the last iterate
//   differs visibly from the one before: after the commit, the return mapping
//   at the converged state from the committed history is elastic (Φ_trial ≤ 0
//   to round-off) and leaves the history unchanged — it would not if the
//   history of the previous iterate had been kept;
// - MPI split (SystemState ranks): every "rank" holds the whole history.
#include "solver/beams/beam_loads.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/plastic_bending.hpp"
#include "tests/solver/beam_test_bodies.hpp"
#include "tests/solver/beam_test_system.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>

using namespace stentsim::solver;
using namespace stentsim::solver::beams;
using namespace stentsim::solver::beams::testing;

namespace {

struct PlasticCantilever {
  PlasticBendingLaw law = PlasticBendingLaw::stent_preset();
  BeamBodyDefinition def;
  std::vector<BeamNodeDofs> dofs;
  GlobalDof ndof = 0;
  std::unique_ptr<BeamTerm> beam;
  std::unique_ptr<NodalLoadTerm> moment;
  double level = 0.0;
  PlasticCantilever() {
    def = curve_body(straight_x(), 0.2, 3, BeamSection::circular_plastic(law));
    dofs = number_beam_dofs(def, 0, &ndof);
    dofs[0].pos = dofs[0].rot = {-1, -1, -1};
    beam = std::make_unique<BeamTerm>("cantilever", def, dofs);
    // a moment about d3 plus a little force: a non-uniform plastic zone
    moment = std::make_unique<NodalLoadTerm>("end moment", dofs[3].rot, Eigen::Vector3d(0, 0.3, 1.0),
                                             [this](double) { return level; });
  }
};

double history_difference(const BeamTerm& b) {
  double d = 0.0;
  for (std::size_t e = 0; e < b.body().elements.size(); ++e)
    for (std::size_t g = 0; g < b.reference(e).points.size(); ++g) {
      const auto &c = b.committed_plastic(e, static_cast<int>(g)), &t = b.trial_plastic(e, static_cast<int>(g));
      d = std::max({d, (c.plastic_curvature - t.plastic_curvature).norm(), std::abs(c.accumulated - t.accumulated)});
    }
  return d;
}

}  // namespace

TEST(BeamCommitState, CommitWithoutAssembleAtTheAcceptedStateThrows) {
  PlasticCantilever c;
  Eigen::VectorXd u = Eigen::VectorXd::Zero(c.ndof);
  DenseAssembler a(c.ndof);
  c.beam->assemble(SystemState{u, 0.0, 0.0}, a);
  Eigen::VectorXd du = Eigen::VectorXd::Zero(c.ndof);
  du[c.dofs[3].rot[2]] = 0.01;
  c.beam->trial(du);
  c.beam->accept();
  EXPECT_THROW(c.beam->commit(), std::logic_error);
  c.beam->assemble(SystemState{u, 0.0, 0.0}, a);  // now at the accepted state
  EXPECT_NO_THROW(c.beam->commit());
}

TEST(BeamCommitState, NewtonCommitsTheHistoryOfTheConvergedState) {
  PlasticCantilever c;
  TestSystem sys(c.ndof);
  sys.terms = {c.beam.get(), c.moment.get()};
  Model model;
  model.dofs.allocate("cantilever", c.ndof);
  model.size_constraints();
  model.add_term<ForwardTerm>(c.beam.get());
  model.add_term<ForwardTerm>(c.moment.get());
  // the clamped root's numbers (set to −1 in the beam's map) are held at zero
  TouchedDofs touched(c.ndof);
  c.beam->assemble(SystemState{sys.u, 0.0, 0.0}, touched);
  for (GlobalDof d = 0; d < c.ndof; ++d)
    if (!touched.touched[static_cast<std::size_t>(d)]) model.constraints.fix(d, [](double) { return 0.0; });
  GlobalSystem system(model.constraints);
  LinearSolverSettings ls;
  ls.type = "eigen_lu";
  auto linear = make_linear_solver(ls);
  NewtonSettings ns;
  ns.residual_tolerance = 1e-3;  // loose: the accepted iterate differs from the previous one
  ns.residual_absolute = 0.0;
  ns.increment_tolerance = 1e-3;
  ns.line_search_steps = 0;
  double final_residual = 0.0;
  int yielded_steps = 0;
  for (double level : {0.05, 0.1, 0.15, 0.2, 0.25}) {
    c.level = level * c.law.M_y0 / 0.08;
    const NewtonResult r = newton_step(model, system, *linear, sys.u, level, 1.0, ns);
    ASSERT_TRUE(r.converged) << r.failure;
    ASSERT_NO_THROW(model.commit());
    final_residual = std::max(final_residual, r.residual_norms.size() > 1 ? r.residual_norms.back() : 0.0);
    // Return again at the converged state from the committed history: no further flow.
    DenseAssembler a(c.ndof);
    c.beam->assemble(SystemState{sys.u, level, 0.0}, a);
    EXPECT_LT(history_difference(*c.beam), 1e-13) << "level " << level;
    for (std::size_t e = 0; e < c.def.elements.size(); ++e)
      if (c.beam->committed_plastic(e, 0).accumulated > 0) {
        ++yielded_steps;
        break;
      }
  }
  EXPECT_GE(yielded_steps, 3);  // the check ran on plastic steps
  EXPECT_GT(final_residual, 1e-10);  // loose: the converged state is not exact, so iterates differ
}

TEST(BeamCommitState, EveryRankHoldsTheWholeHistory) {
  // Two "ranks" assemble their halves into separate assemblers: both end with
  // the history of every element, equal to the serial one.
  auto run = [](int rank, int ranks) {
    PlasticCantilever c;
    Eigen::VectorXd u = Eigen::VectorXd::Zero(c.ndof);
    // triads turned about d3 by κ·x with κ = 0.3/mm (yield at 0.02/mm) and a twist
    Eigen::VectorXd du = Eigen::VectorXd::Zero(c.ndof);
    for (std::size_t n = 0; n < c.def.nodes.size(); ++n) {
      const double x = c.def.nodes[n].position.x();
      if (c.dofs[n].rot[2] >= 0) du[c.dofs[n].rot[2]] = 0.3 * x + 0.2 * x * x, du[c.dofs[n].rot[0]] = 0.05 * x;
    }
    c.beam->trial(du);
    c.beam->accept();
    DenseAssembler a(c.ndof);
    c.beam->assemble(SystemState{u, 0.0, 0.0, rank, ranks}, a);
    c.beam->commit();
    std::vector<double> h;
    for (std::size_t e = 0; e < c.def.elements.size(); ++e)
      for (std::size_t g = 0; g < c.beam->reference(e).points.size(); ++g)
        h.push_back(c.beam->committed_plastic(e, static_cast<int>(g)).accumulated);
    return std::make_pair(h, c.beam->plastic_work());
  };
  const auto serial = run(0, 1);
  double yielded = 0;
  for (double x : serial.first) yielded = std::max(yielded, x);
  ASSERT_GT(yielded, 0.0);
  for (int rank = 0; rank < 2; ++rank) {
    const auto part = run(rank, 2);
    ASSERT_EQ(part.first.size(), serial.first.size());
    for (std::size_t i = 0; i < serial.first.size(); ++i) EXPECT_EQ(part.first[i], serial.first[i]) << "rank " << rank;
    EXPECT_EQ(part.second, serial.second);
  }
}
