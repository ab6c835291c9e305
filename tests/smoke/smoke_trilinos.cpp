// Smoke test: Tpetra matrix assembled over the MPI ranks, solved by Belos
// GMRES with an Ifpack2 ILU(k) preconditioner. Run under mpirun with 1 and 2
// ranks; exits non-zero when the solution is wrong.
#include <BelosLinearProblem.hpp>
#include <BelosSolverFactory.hpp>
#include <BelosTpetraAdapter.hpp>
#include <Ifpack2_Factory.hpp>
#include <Teuchos_GlobalMPISession.hpp>
#include <Tpetra_Core.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Vector.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  Tpetra::ScopeGuard scope(&argc, &argv);
  using SC = double;
  using LO = int;
  using GO = long long;
  using Map = Tpetra::Map<LO, GO>;
  using MAT = Tpetra::CrsMatrix<SC, LO, GO>;
  using MV = Tpetra::MultiVector<SC, LO, GO>;
  using OP = Tpetra::Operator<SC, LO, GO>;
  auto comm = Tpetra::getDefaultComm();
  const GO n = 2000;
  auto map = Teuchos::rcp(new Map(n, 0, comm));
  auto A = Teuchos::rcp(new MAT(map, 3));
  // 1D Laplacian with a shift: exact solution x = 1 for b = A*1.
  for (LO l = 0; l < static_cast<LO>(map->getNodeNumElements()); ++l) {
    const GO i = map->getGlobalElement(l);
    std::vector<GO> cols{i};
    std::vector<SC> vals{2.1};
    if (i > 0) cols.push_back(i - 1), vals.push_back(-1.0);
    if (i < n - 1) cols.push_back(i + 1), vals.push_back(-1.0);
    A->insertGlobalValues(i, Teuchos::ArrayView<const GO>(cols), Teuchos::ArrayView<const SC>(vals));
  }
  A->fillComplete();
  auto x_exact = Teuchos::rcp(new MV(map, 1));
  x_exact->putScalar(1.0);
  auto b = Teuchos::rcp(new MV(map, 1));
  A->apply(*x_exact, *b);
  auto x = Teuchos::rcp(new MV(map, 1));
  x->putScalar(0.0);

  Ifpack2::Factory factory;
  auto prec = factory.create<Tpetra::RowMatrix<SC, LO, GO>>("RILUK", A);
  Teuchos::ParameterList pp;
  pp.set("fact: iluk level-of-fill", 4);
  prec->setParameters(pp);
  prec->initialize();
  prec->compute();

  auto problem = Teuchos::rcp(new Belos::LinearProblem<SC, MV, OP>(A, x, b));
  problem->setRightPrec(prec);
  problem->setProblem();
  auto params = Teuchos::rcp(new Teuchos::ParameterList);
  params->set("Num Blocks", 200);
  params->set("Maximum Iterations", 1000);
  params->set("Convergence Tolerance", 1e-10);
  Belos::SolverFactory<SC, MV, OP> solvers;
  auto solver = solvers.create("GMRES", params);
  solver->setProblem(problem);
  const auto result = solver->solve();

  x->update(-1.0, *x_exact, 1.0);
  Teuchos::Array<SC> err(1);
  x->normInf(err());
  // argv[1]: the rank count mpirun was asked for; a run that silently fell
  // back to one process must not pass as the 2-rank test.
  const int expected_ranks = argc > 1 ? std::atoi(argv[1]) : comm->getSize();
  const bool ok = result == Belos::Converged && err[0] < 1e-6 && comm->getSize() == expected_ranks;
  if (comm->getRank() == 0)
    std::printf("trilinos smoke: ranks=%d iterations=%d max error=%.3e -> %s\n", comm->getSize(), solver->getNumIters(),
                err[0], ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
