#include "workflows/study/stability/child_run.hpp"

#include <chrono>

namespace fs = std::filesystem;

namespace stentsim::study {

ChildRun run_child(const std::vector<std::string>& argv, const fs::path& cwd, const fs::path& log, double limit_s) {
  fs::create_directories(cwd);
  process::ChildSetup setup;
  setup.cwd = cwd;
  setup.log = log;
  setup.env = process::single_thread_environment();
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = process::spawn_exec(argv, setup);
  return process::wait_with_limit(pid, start, limit_s);
}

}  // namespace stentsim::study
