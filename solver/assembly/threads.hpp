#pragma once
// Threads of a solve's element loops (DESIGN.md §2: one rank holds one
// partition; inside it, terms with many elements may split their loop over
// threads). One count per process, set for the life of a solve by an
// AssemblyThreads scope; 1 outside one, so tools and tests that assemble a term
// directly keep its serial order. TBB stays behind threads.cpp.
#include <cstddef>
#include <functional>

namespace stentsim::solver {

/// The threads an element loop may use now (>= 1).
int assembly_threads();

/// This thread's index among assembly_threads() inside parallel_ranges (0 outside).
int assembly_thread_index();

/// The count a solve takes when none is given: $STENTSIM_THREADS when set (a
/// cohort worker sets 1), else the cores this process may run on shared by
/// `ranks` ranks on this node. A malformed $STENTSIM_THREADS is an InputError.
int default_assembly_threads(int ranks);

/// Sets assembly_threads() to `threads` for its lifetime.
class AssemblyThreads {
 public:
  explicit AssemblyThreads(int threads);
  ~AssemblyThreads();
  AssemblyThreads(const AssemblyThreads&) = delete;
  AssemblyThreads& operator=(const AssemblyThreads&) = delete;

 private:
  int previous_;
};

/// Calls body(begin, end) over chunks of [0, n) of about `grain` items on
/// assembly_threads() threads, and returns when all have run (in this thread
/// alone, in order, when the count is 1). The first exception thrown by a chunk
/// is rethrown here once every chunk has stopped.
void parallel_ranges(std::size_t n, std::size_t grain, const std::function<void(std::size_t, std::size_t)>& body);

/// How many buffers a parallel_ordered loop started now may fill at once (>= 1).
int ordered_slots();

/// An element loop whose blocks reach the assembler in serial order while their
/// work runs in parallel: over chunks of [0, n) of `grain` items, compute(begin,
/// end, slot) on assembly_threads() threads, and consume(begin, end, slot) for
/// each chunk, one chunk at a time and in chunk order, after its compute. So
/// every sum the consumer makes is the one-thread loop's, bit for bit, with no
/// colouring: for terms whose blocks move with the state (contact) or whose
/// scatter is a small share. `slot` < ordered_slots() names the buffer a chunk's
/// compute fills and its consume reads: no two chunks in flight share one. A
/// compute that throws stops the loop at its chunk's turn, so the exception
/// rethrown here is the first in chunk order, as in the serial loop; up to
/// ordered_slots() - 1 later chunks may have been computed by then but are not
/// consumed. So a compute writes only its slot and state of its own items that
/// the next complete loop overwrites; what must stay in step with the assembler
/// is changed in consume.
void parallel_ordered(std::size_t n, std::size_t grain, const std::function<void(std::size_t, std::size_t, int)>& compute,
                      const std::function<void(std::size_t, std::size_t, int)>& consume);

}  // namespace stentsim::solver
