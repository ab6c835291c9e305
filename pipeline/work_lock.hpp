#pragma once
// An exclusive lock on a case's work folder, so two runners never write the
// same case. flock() is released by the kernel when the holder dies; a lock
// file that still names a dead holder is reported as a stale lock taken over.
#include <filesystem>
#include <string>

namespace stentsim::pipeline {

class WorkLock {
 public:
  /// Takes the lock or throws InputError naming the process that holds it.
  explicit WorkLock(const std::filesystem::path& work_dir);
  ~WorkLock();
  WorkLock(const WorkLock&) = delete;
  WorkLock& operator=(const WorkLock&) = delete;

  /// Non-empty when a previous holder died without releasing (its description).
  const std::string& stale_holder() const { return stale_holder_; }

 private:
  int fd_ = -1;
  std::filesystem::path file_;
  std::string stale_holder_;
};

}  // namespace stentsim::pipeline
