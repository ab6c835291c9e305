#pragma once
// The mutations every reader fuzz test applies to copies of valid files, and
// the loop that judges each mutant: it must either read (a valid input) or
// fail with an InputError naming the file; a crash, a hang, std::bad_alloc or
// any other exception fails the test, as does a read that takes more than
// seconds_allowed() or whose peak resident memory exceeds what the process
// held before it plus megabytes_allowed(). A fixed seed; 300 mutants per format in
// the quick set, STENTSIM_FUZZ_ITERATIONS more (the validation variants).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>

#include "common/error.hpp"

namespace stentsim::fuzz {

inline int iterations() {
  const char* n = std::getenv("STENTSIM_FUZZ_ITERATIONS");
  return n ? std::max(1, std::atoi(n)) : 300;
}

/// The time a clear error must come within (the hardening target: 30 s for any input under 10 MB);
/// STENTSIM_FUZZ_SECONDS raises it for instrumented builds, which judge memory errors,
/// not speed (scripts/run-sanitizers.sh: ASan reads a mutant's huge blocks many times slower).
inline double seconds_allowed() {
  const char* s = std::getenv("STENTSIM_FUZZ_SECONDS");
  return s ? std::max(1.0, std::atof(s)) : 30.0;
}

/// The memory a read may add (the hardening target: 2 GB for any input under 10 MB);
/// STENTSIM_FUZZ_MEGABYTES raises it for instrumented builds.
inline double megabytes_allowed() {
  const char* s = std::getenv("STENTSIM_FUZZ_MEGABYTES");
  return s ? std::max(1.0, std::atof(s)) : 2048.0;
}

/// This process's resident memory now, in MB (Linux: statm).
inline double resident_megabytes() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  unsigned long size = 0, resident = 0;
  const bool ok = f && std::fscanf(f, "%lu %lu", &size, &resident) == 2;
  if (f) std::fclose(f);
  return ok ? static_cast<double>(resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / 1048576.0 : 0.0;
}

/// Sets the peak resident memory (VmHWM) back to the resident memory now
/// (Linux: "5" to /proc/self/clear_refs), so that the next peak is one read's.
/// False where the kernel refuses: the peak then covers everything so far.
inline bool reset_peak_resident() {
  std::FILE* f = std::fopen("/proc/self/clear_refs", "w");
  if (!f) return false;
  const bool ok = std::fputs("5", f) >= 0;
  return std::fclose(f) == 0 && ok;
}

/// The peak resident memory since the last reset_peak_resident(), in MB (VmHWM).
inline double peak_resident_megabytes() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0.0;
  char line[256];
  double kb = 0.0;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "VmHWM: %lf kB", &kb) == 1) break;
  std::fclose(f);
  return kb / 1024.0;
}

/// One mutation of `seed`: a few bit flips, a byte run inserted or deleted, a cut,
/// a number replaced by a huge one, "nan" or four raw bytes (a binary count,
/// offset or coordinate) overwritten.
inline std::string mutate(const std::string& seed, std::mt19937& gen) {
  std::string s = seed;
  std::uniform_int_distribution<int> kind(0, 6);
  auto at = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n ? n - 1 : 0)(gen); };
  if (s.empty()) return s;
  switch (kind(gen)) {
    case 0:
      for (int k = 0; k < 1 + static_cast<int>(at(8)); ++k) s[at(s.size())] ^= static_cast<char>(1 << at(8));
      break;
    case 1: s.insert(at(s.size()), std::string(1 + at(16), static_cast<char>(at(256)))); break;
    case 2: {
      const std::size_t p = at(s.size());
      s.erase(p, 1 + at(64));
      break;
    }
    case 3: s.resize(at(s.size())); break;
    case 4: {  // a digit run replaced by a huge count
      const std::size_t p = s.find_first_of("0123456789", at(s.size()));
      if (p != std::string::npos) s.replace(p, s.find_first_not_of("0123456789", p) - p, "4294967295");
      break;
    }
    case 5: {
      const std::size_t p = s.find_first_of("0123456789", at(s.size()));
      if (p != std::string::npos) s.replace(p, 1, "nan");
      break;
    }
    default: {
      const std::uint32_t v = std::uniform_int_distribution<std::uint32_t>()(gen);
      if (s.size() > 4) std::memcpy(s.data() + at(s.size() - 4), &v, 4);
      break;
    }
  }
  return s;
}

inline void write_file(const std::filesystem::path& f, const std::string& bytes) {
  std::ofstream out(f, std::ios::binary | std::ios::trunc);
  out << bytes;
}

/// A failing mutant copied where the next run does not overwrite it, to reproduce the failure.
inline std::string keep(const std::filesystem::path& f) {
  std::error_code ec;
  const auto copy = std::filesystem::temp_directory_path() / ("stentsim_fuzz_failing_" + f.filename().string());
  std::filesystem::copy_file(f, copy, std::filesystem::copy_options::overwrite_existing, ec);
  return ec ? std::string() : " (kept as " + copy.string() + ")";
}

struct Tally {
  int read = 0, refused = 0;
};

/// Runs `read` on n mutants that `make(i)` writes (returning the file the error
/// must name); counts valid reads and input errors, fails on anything else, on
/// a mutant that takes longer than seconds_allowed() (a clear error must come within that)
/// and on one whose read takes the peak resident memory above the resident memory
/// before it plus megabytes_allowed() (the peak is reset before each read; where the
/// kernel refuses, the bound is the judge's start's and the peak the process's own).
inline Tally judge(const std::string& format, int n, const std::function<std::filesystem::path(int)>& make,
                   const std::function<void(const std::filesystem::path&)>& read) {
  Tally t;
  double memory_bound = std::max(resident_megabytes(), peak_resident_megabytes()) + megabytes_allowed(), largest = 0.0;
  for (int i = 0; i < n; ++i) {
    const std::filesystem::path named = make(i);
    if (reset_peak_resident()) memory_bound = resident_megabytes() + megabytes_allowed();
    const auto start = std::chrono::steady_clock::now();
    try {
      read(named);
      ++t.read;
    } catch (const InputError& e) {
      ++t.refused;
      EXPECT_NE(std::string(e.what()).find(named.string()), std::string::npos) << format << " mutant " << i << ": " << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << format << " mutant " << i << ": not an InputError: " << e.what() << keep(named);
      return t;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, seconds_allowed()) << format << " mutant " << i << " took " << seconds << " s";
    const double peak = peak_resident_megabytes();
    largest = std::max(largest, peak);
    if (peak >= memory_bound) {
      ADD_FAILURE() << format << " mutant " << i << ": peak resident memory " << peak << " MB, above " << memory_bound << " MB"
                    << keep(named);
      return t;
    }
    if (::testing::Test::HasFatalFailure()) return t;
  }
  std::printf("%-16s %d mutants: %d read, %d refused with an input error; largest peak resident memory %.0f MB (bound %.0f)\n",
              format.c_str(), n, t.read, t.refused, largest, memory_bound);
  std::fflush(stdout);
  return t;
}

}  // namespace stentsim::fuzz
