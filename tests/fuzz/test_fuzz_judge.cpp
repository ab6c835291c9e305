// The fuzz judge itself: a read that stays within the bounds passes, one that
// takes the process's peak resident memory above megabytes_allowed() fails.
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>

#include "tests/fuzz/mutation.hpp"

namespace fs = std::filesystem;

namespace {

void judge_one_read(std::size_t touched_bytes) {
  const fs::path f = fs::temp_directory_path() / ("stentsim_fuzz_judge_" + std::to_string(::getpid()));
  stentsim::fuzz::write_file(f, "x");
  stentsim::fuzz::judge(
      "judge", 1, [&](int) { return f; },
      [&](const fs::path&) {
        std::unique_ptr<char[]> block(new char[touched_bytes]);
        std::memset(block.get(), 1, touched_bytes);  // resident, not just reserved
        volatile char keep = block[touched_bytes - 1];
        (void)keep;
      });
  fs::remove(f);
}

}  // namespace

TEST(FuzzJudge, AReadAboveTheMemoryBoundFails) {
  // The bound is the resident memory when judging starts plus this many MB.
  ::setenv("STENTSIM_FUZZ_MEGABYTES", "32", 1);
  judge_one_read(std::size_t{1} << 20);  // 1 MB: within
  EXPECT_NONFATAL_FAILURE(judge_one_read(std::size_t{96} << 20), "peak resident memory");
  ::unsetenv("STENTSIM_FUZZ_MEGABYTES");
}
