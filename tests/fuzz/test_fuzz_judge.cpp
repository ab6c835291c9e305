// The fuzz judge itself: a read that stays within the bounds passes, one that
// takes the process's peak resident memory above megabytes_allowed() fails.
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

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
        volatile char* where = block.get();  // volatile stores: the optimizer keeps every page's write
        for (std::size_t i = 0; i < touched_bytes; i += 4096) where[i] = 1;  // resident, not just reserved
      });
  fs::remove(f);
}

}  // namespace

TEST(FuzzJudge, AReadAboveTheMemoryBoundFails) {
  // The bound is the resident memory before a read plus this many MB.
  const char* inherited = std::getenv("STENTSIM_FUZZ_MEGABYTES");
  const std::string kept = inherited ? inherited : "";
  ::setenv("STENTSIM_FUZZ_MEGABYTES", "32", 1);
  judge_one_read(std::size_t{1} << 20);  // 1 MB: within
  EXPECT_NONFATAL_FAILURE(judge_one_read(std::size_t{96} << 20), "peak resident memory");
  judge_one_read(std::size_t{1} << 20);  // the peak is a read's own: the large one before does not count
  if (inherited) ::setenv("STENTSIM_FUZZ_MEGABYTES", kept.c_str(), 1);
  else ::unsetenv("STENTSIM_FUZZ_MEGABYTES");
  std::error_code ec;  // the failing read's copy, kept by the judge
  fs::remove(fs::temp_directory_path() / ("stentsim_fuzz_failing_stentsim_fuzz_judge_" + std::to_string(::getpid())), ec);
}
