#include "pipeline/work_lock.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "common/error.hpp"
#include "pipeline/manifest.hpp"

namespace stentsim::pipeline {
namespace {
std::string read_all(int fd) {
  std::string s;
  char buf[256];
  ::lseek(fd, 0, SEEK_SET);
  ssize_t n;
  while ((n = ::read(fd, buf, sizeof buf)) > 0) s.append(buf, static_cast<std::size_t>(n));
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}
}  // namespace

WorkLock::WorkLock(const std::filesystem::path& work_dir) : file_(work_dir / ".lock") {
  std::filesystem::create_directories(work_dir);
  fd_ = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(fmt::format("{}: cannot open the work-folder lock: {}", file_.string(), std::strerror(errno)));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    std::string holder = read_all(fd_);
    ::close(fd_);
    fd_ = -1;
    throw InputError(fmt::format("{}: the case is being run by another stentsim ({}); wait for it or stop it",
                                 work_dir.string(), holder.empty() ? "unknown process" : holder));
  }
  stale_holder_ = read_all(fd_);
  char host[256] = {0};
  ::gethostname(host, sizeof host - 1);
  std::string me = fmt::format("pid {} on {} since {}", ::getpid(), host, utc_now_iso8601());
  if (::ftruncate(fd_, 0) == 0) {
    ::lseek(fd_, 0, SEEK_SET);
    [[maybe_unused]] auto w = ::write(fd_, me.data(), me.size());
  }
}

WorkLock::~WorkLock() {
  if (fd_ < 0) return;
  [[maybe_unused]] int rc = ::ftruncate(fd_, 0);
  ::flock(fd_, LOCK_UN);
  ::close(fd_);
}

}  // namespace stentsim::pipeline
