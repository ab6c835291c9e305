#include "solver/assembly/threads.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <string>

#include "common/error.hpp"

namespace stentsim::solver {
namespace {

int threads_now = 1;
// One arena per count, made when a scope first asks for it: the workers of an
// arena live as long as it does, so each assembly reuses them.
std::unique_ptr<tbb::task_arena> arena;

}  // namespace

int assembly_threads() { return threads_now; }

int assembly_thread_index() {
  const int i = tbb::this_task_arena::current_thread_index();
  return i == tbb::task_arena::not_initialized ? 0 : i;
}

int default_assembly_threads(int ranks) {
  if (const char* env = std::getenv("STENTSIM_THREADS"); env && *env) {
    char* end = nullptr;
    const long n = std::strtol(env, &end, 10);
    if (*end != '\0' || n < 1 || n > 1024)
      throw InputError(fmt::format("environment variable STENTSIM_THREADS = '{}': expected a whole number of threads "
                                   "from 1 to 1024 (unset it to use the cores this process may run on)", env));
    return static_cast<int>(n);
  }
  return std::max(1, tbb::info::default_concurrency() / std::max(1, ranks));
}

AssemblyThreads::AssemblyThreads(int threads) : previous_(threads_now) {
  threads_now = std::max(1, threads);
  if (threads_now > 1 && (!arena || arena->max_concurrency() != threads_now))
    arena = std::make_unique<tbb::task_arena>(threads_now);
}

AssemblyThreads::~AssemblyThreads() { threads_now = previous_; }

void parallel_ranges(std::size_t n, std::size_t grain, const std::function<void(std::size_t, std::size_t)>& body) {
  if (threads_now <= 1 || n <= grain || !arena) {
    if (n > 0) body(0, n);
    return;
  }
  arena->execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, std::max<std::size_t>(1, grain)),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
  });
}

}  // namespace stentsim::solver
