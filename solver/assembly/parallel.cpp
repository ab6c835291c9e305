#include "solver/assembly/parallel.hpp"

#include <mpi.h>

#include <vector>

namespace stentsim::solver::parallel {
namespace {
bool active() {
  int init = 0, fin = 0;
  MPI_Initialized(&init);
  MPI_Finalized(&fin);
  if (!init || fin) return false;
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n > 1;
}
}  // namespace

int rank() {
  if (!active()) return 0;
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

int size() {
  if (!active()) return 1;
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

void sum(Eigen::VectorXd& v) {
  if (!active()) return;
  MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
}

bool any(bool flag) {
  if (!active()) return flag;
  int f = flag ? 1 : 0, g = 0;
  MPI_Allreduce(&f, &g, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return g != 0;
}

std::string first_message(bool flag, const std::string& message) {
  if (!active()) return flag ? message : std::string();
  const int me = rank();
  int who = flag ? me : 1 << 30, first = 0;
  MPI_Allreduce(&who, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == 1 << 30) return {};
  int len = me == first ? static_cast<int>(message.size()) : 0;
  MPI_Bcast(&len, 1, MPI_INT, first, MPI_COMM_WORLD);
  std::vector<char> buf(static_cast<std::size_t>(len) + 1, 0);
  if (me == first) std::copy(message.begin(), message.end(), buf.begin());
  MPI_Bcast(buf.data(), len, MPI_CHAR, first, MPI_COMM_WORLD);
  return std::string(buf.data(), static_cast<std::size_t>(len));
}

}  // namespace stentsim::solver::parallel
