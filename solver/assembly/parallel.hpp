#pragma once
// The few MPI operations the assembly and the nonlinear solver need. Every
// rank holds the whole state vector; element contributions are split by
// rank (SystemState::owns) and summed here. Without MPI initialised (plain
// runs, unit tests) everything is rank 0 of 1.
#include <Eigen/Core>

#include <string>

namespace stentsim::solver::parallel {

int rank();
int size();
/// Element-wise sum over ranks (in place).
void sum(Eigen::VectorXd& v);
/// Max over ranks of a flag; true on every rank if any rank set it.
bool any(bool flag);
/// The message of the lowest rank whose flag is set (empty if none).
std::string first_message(bool flag, const std::string& message);

}  // namespace stentsim::solver::parallel
