// common/heap_policy: after keep_large_blocks() a large block freed and
// allocated again reuses resident pages (no new page faults), where glibc's
// default maps and faults it in afresh every time; the user's malloc
// environment wins over the policy.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <memory>

#include "common/heap_policy.hpp"

namespace {

// Minor page faults while a block of `bytes` is allocated, written and freed.
long faults_for_one_block(std::size_t bytes) {
  rusage before{}, after{};
  ::getrusage(RUSAGE_SELF, &before);
  {
    std::unique_ptr<char[]> block(new char[bytes]);
    std::memset(block.get(), 1, bytes);
    volatile char keep = block[bytes / 2];
    (void)keep;
  }
  ::getrusage(RUSAGE_SELF, &after);
  return after.ru_minflt - before.ru_minflt;
}

}  // namespace

TEST(CommonHeapPolicy, ALargeBlockReusesItsPagesOnlyUnderThePolicy) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer replaces malloc";
#else
  const std::size_t bytes = std::size_t{64} << 20;  // above glibc's largest mmap threshold (32 MB)
  const long pages = static_cast<long>(bytes / 4096);
  // glibc's default: mmap'd, so every round faults every page in again.
  faults_for_one_block(bytes);
  EXPECT_GT(faults_for_one_block(bytes), pages / 2);
  ::setenv("MALLOC_MMAP_MAX_", "65536", 1);
  EXPECT_FALSE(stentsim::heap::keep_large_blocks());  // the user's setting stands
  ::unsetenv("MALLOC_MMAP_MAX_");
  ASSERT_TRUE(stentsim::heap::keep_large_blocks());
  faults_for_one_block(bytes);  // the heap grows once
  EXPECT_LT(faults_for_one_block(bytes), pages / 20);
#endif
}
