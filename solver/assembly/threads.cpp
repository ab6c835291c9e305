#include "solver/assembly/threads.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

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

int ordered_slots() { return threads_now > 1 && arena ? 2 * threads_now : 1; }

void parallel_ordered(std::size_t n, std::size_t grain, const std::function<void(std::size_t, std::size_t, int)>& compute,
                      const std::function<void(std::size_t, std::size_t, int)>& consume) {
  grain = std::max<std::size_t>(1, grain);
  const std::size_t chunks = (n + grain - 1) / grain;
  const int slots = ordered_slots();
  auto range = [&](std::size_t c) { return std::pair{c * grain, std::min(n, c * grain + grain)}; };
  if (slots == 1 || chunks <= 1) {
    for (std::size_t c = 0; c < chunks; ++c) {
      const auto [begin, end] = range(c);
      compute(begin, end, 0);
      consume(begin, end, 0);
    }
    return;
  }
  // A pipeline of `slots` tokens: chunks are taken in order, computed in parallel and
  // consumed in order. Chunk c + slots is taken only once a token is free, and tokens
  // come free in chunk order (the last stage is in order), so chunk c has been consumed
  // by then: slot c % slots is never shared by two chunks in flight.
  std::vector<std::exception_ptr> failed(static_cast<std::size_t>(slots));
  std::size_t next = 0;
  arena->execute([&] {
    tbb::parallel_pipeline(
        static_cast<std::size_t>(slots),
        tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                            [&](tbb::flow_control& fc) -> std::size_t {
                                              if (next == chunks) {
                                                fc.stop();
                                                return 0;
                                              }
                                              return next++;
                                            }) &
            tbb::make_filter<std::size_t, std::size_t>(tbb::filter_mode::parallel,
                                                       [&](std::size_t c) {
                                                         const int s = static_cast<int>(c % static_cast<std::size_t>(slots));
                                                         const auto [begin, end] = range(c);
                                                         failed[static_cast<std::size_t>(s)] = nullptr;
                                                         try {
                                                           compute(begin, end, s);
                                                         } catch (...) {
                                                           failed[static_cast<std::size_t>(s)] = std::current_exception();
                                                         }
                                                         return c;
                                                       }) &
            tbb::make_filter<std::size_t, void>(tbb::filter_mode::serial_in_order, [&](std::size_t c) {
              const int s = static_cast<int>(c % static_cast<std::size_t>(slots));
              if (failed[static_cast<std::size_t>(s)]) std::rethrow_exception(failed[static_cast<std::size_t>(s)]);
              const auto [begin, end] = range(c);
              consume(begin, end, s);
            }));
  });
}

}  // namespace stentsim::solver
