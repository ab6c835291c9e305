#pragma once
// Runs the stentsim binary under test and captures its output and exit code.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace stentsim::testing {

struct CliResult {
  int code;
  std::string out;  // stdout and stderr together
};

inline CliResult run_stentsim(const std::string& args) {
  const std::string cmd = std::string(STENTSIM_TEST_BINARY) + " " + args + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int status = ::pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace stentsim::testing
