// common/heap_policy: under glibc's defaults a large block is mmap'd (mallinfo2's
// hblkhd counts it) and each round faults its pages in again; after
// keep_large_blocks() it comes from the heap and a second round reuses
// resident pages. The user's malloc environment wins over the policy.
#include <gtest/gtest.h>
#include <malloc.h>
#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <memory>

#include "common/heap_policy.hpp"

namespace {

struct Round {
  std::size_t mapped = 0;  // mallinfo2().hblkhd while the block lives
  long faults = 0;         // minor page faults of the round
};

// Allocates, writes and frees a block of `bytes`.
Round one_block(std::size_t bytes) {
  rusage before{}, after{};
  ::getrusage(RUSAGE_SELF, &before);
  Round r;
  {
    std::unique_ptr<char[]> block(new char[bytes]);
    volatile char* where = block.get();  // volatile stores: the optimizer keeps every page's write
    for (std::size_t i = 0; i < bytes; i += 4096) where[i] = 1;
    r.mapped = ::mallinfo2().hblkhd;
  }
  ::getrusage(RUSAGE_SELF, &after);
  r.faults = after.ru_minflt - before.ru_minflt;
  return r;
}

}  // namespace

TEST(CommonHeapPolicy, ALargeBlockComesFromTheHeapOnlyUnderThePolicy) {
  if (std::getenv("MALLOC_MMAP_MAX_") || std::getenv("MALLOC_TRIM_THRESHOLD_") || std::getenv("MALLOC_MMAP_THRESHOLD_") ||
      std::getenv("GLIBC_TUNABLES"))
    GTEST_SKIP() << "the environment sets glibc's malloc options";
  const std::size_t bytes = std::size_t{64} << 20;  // above glibc's largest mmap threshold (32 MB)
  const Round plain = one_block(bytes);
  if (plain.mapped < bytes) GTEST_SKIP() << "this allocator does not mmap large blocks (a sanitizer's?)";
  ::setenv("MALLOC_MMAP_MAX_", "65536", 1);
  EXPECT_FALSE(stentsim::heap::keep_large_blocks());  // the user's setting stands
  ::unsetenv("MALLOC_MMAP_MAX_");
  ASSERT_TRUE(stentsim::heap::keep_large_blocks());
  const Round first = one_block(bytes);  // the heap grows once
  EXPECT_LT(first.mapped, bytes);
  const Round again = one_block(bytes);
  EXPECT_LT(again.mapped, bytes);
  // The pages the first round faulted in serve the second (huge pages or not).
  EXPECT_LT(again.faults, std::max<long>(1, first.faults) / 4 + 16) << "first round " << first.faults << " faults";
}
