#pragma once
// A small logger: messages to stderr and, when set, to a log file; progress
// lines for long work. Stages log through this so logs land in the case's
// work folder (logs/<stage>.log).
#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <string>

namespace stentsim::log {

enum class Level { debug, info, warn, error };

void set_level(Level level);
/// Also write every message to `file` (appending). Empty path: stderr only.
void set_file(const std::filesystem::path& file);
/// A prefix for every line, e.g. the stage name.
void set_prefix(const std::string& prefix);
void write(Level level, const std::string& message);

template <typename... Args>
void info(fmt::format_string<Args...> f, Args&&... args) {
  write(Level::info, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void warn(fmt::format_string<Args...> f, Args&&... args) {
  write(Level::warn, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void error(fmt::format_string<Args...> f, Args&&... args) {
  write(Level::error, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void debug(fmt::format_string<Args...> f, Args&&... args) {
  write(Level::debug, fmt::format(f, std::forward<Args>(args)...));
}

/// Progress of a long task: prints "what: 40% (4/10), ETA 12 s" at most every
/// `interval` and always at the end.
class Progress {
 public:
  Progress(std::string what, std::size_t total, std::chrono::milliseconds interval = std::chrono::milliseconds(1000));
  void update(std::size_t done);
  void finish();

 private:
  std::string what_;
  std::size_t total_;
  std::chrono::milliseconds interval_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace stentsim::log
