#include "common/log.hpp"

#include <cstdio>
#include <fstream>
#include <mutex>

namespace stentsim::log {
namespace {
struct State {
  Level level = Level::info;
  std::ofstream file;
  std::string prefix;
  std::mutex mutex;
};
State& state() {
  static State s;
  return s;
}
const char* tag(Level l) {
  switch (l) {
    case Level::debug: return "debug";
    case Level::info: return "info";
    case Level::warn: return "warning";
    case Level::error: return "error";
  }
  return "";
}
}  // namespace

void set_level(Level level) { state().level = level; }

void set_file(const std::filesystem::path& file) {
  std::lock_guard lock(state().mutex);
  state().file.close();
  if (!file.empty()) {
    std::filesystem::create_directories(file.parent_path());
    state().file.open(file, std::ios::app);
  }
}

void set_prefix(const std::string& prefix) { state().prefix = prefix; }

void write(Level level, const std::string& message) {
  auto& s = state();
  std::lock_guard lock(s.mutex);
  if (s.file.is_open()) s.file << "[" << tag(level) << "] " << message << "\n" << std::flush;
  if (level < s.level) return;
  std::string line = s.prefix.empty() ? "" : "[" + s.prefix + "] ";
  if (level >= Level::warn) line += std::string(tag(level)) + ": ";
  line += message;
  std::fprintf(stderr, "%s\n", line.c_str());
}

Progress::Progress(std::string what, std::size_t total, std::chrono::milliseconds interval)
    : what_(std::move(what)), total_(total), interval_(interval), start_(std::chrono::steady_clock::now()), last_(start_) {}

void Progress::update(std::size_t done) {
  auto now = std::chrono::steady_clock::now();
  if (now - last_ < interval_ && done < total_) return;
  last_ = now;
  double elapsed = std::chrono::duration<double>(now - start_).count();
  double frac = total_ ? static_cast<double>(done) / static_cast<double>(total_) : 1.0;
  std::string eta = frac > 0 && frac < 1 ? fmt::format(", ETA {:.0f} s", elapsed * (1 - frac) / frac) : "";
  info("{}: {:.0f}% ({}/{}){}", what_, 100 * frac, done, total_, eta);
}

void Progress::finish() {
  double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  info("{}: done in {:.2f} s", what_, elapsed);
}

}  // namespace stentsim::log
