#include "common/files.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "common/error.hpp"

namespace fs = std::filesystem;

namespace stentsim::files {
namespace {

std::string hex128(XXH128_hash_t h) { return fmt::format("{:016x}{:016x}", h.high64, h.low64); }

struct StateDeleter {
  void operator()(XXH3_state_t* s) const { XXH3_freeState(s); }
};

void hash_file_into(XXH3_state_t* state, const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot be read", file.string()));
  std::vector<char> buf(1 << 20);
  while (in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    XXH3_128bits_update(state, buf.data(), static_cast<std::size_t>(in.gcount()));
  }
}

}  // namespace

fs::path temporary_name_for(const fs::path& target) {
  return target.parent_path() / fmt::format(".{}.tmp-{}", target.filename().string(), ::getpid());
}

void write_atomic(const fs::path& target, const std::string& content) {
  if (!target.parent_path().empty()) fs::create_directories(target.parent_path());
  const fs::path tmp = temporary_name_for(target);
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw ComputeError(fmt::format("{}: cannot write: {}", tmp.string(), std::strerror(errno)));
  std::size_t done = 0;
  while (done < content.size()) {
    ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      int err = errno;
      ::close(fd);
      fs::remove(tmp);
      throw ComputeError(fmt::format("{}: write failed: {}", tmp.string(), std::strerror(err)));
    }
    done += static_cast<std::size_t>(n);
  }
  ::fsync(fd);
  ::close(fd);
  replace(tmp, target);
}

void replace(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  if (fs::is_directory(from) && fs::exists(to)) fs::remove_all(to, ec);
  fs::rename(from, to, ec);
  if (ec) throw ComputeError(fmt::format("cannot rename {} to {}: {}", from.string(), to.string(), ec.message()));
}

void require_regular_file(const fs::path& file, const std::string& what) {
  std::error_code ec;
  const auto st = fs::status(file, ec);
  if (!fs::exists(st)) throw InputError(fmt::format("{}: file not found", file.string()));
  if (!fs::is_regular_file(st))
    throw InputError(fmt::format("{}: not a regular file (a folder, device or pipe); give the {} itself", file.string(), what));
}

std::string read_text(const fs::path& file) {
  require_regular_file(file);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot be read", file.string()));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string content_hash(const fs::path& path) {
  std::unique_ptr<XXH3_state_t, StateDeleter> state(XXH3_createState());
  XXH3_128bits_reset(state.get());
  if (fs::is_directory(path)) {
    std::vector<fs::path> entries;
    for (const auto& e : fs::recursive_directory_iterator(path))
      if (e.is_regular_file()) entries.push_back(e.path());
    std::sort(entries.begin(), entries.end());
    for (const auto& e : entries) {
      const std::string rel = fs::relative(e, path).generic_string();
      XXH3_128bits_update(state.get(), rel.data(), rel.size() + 1);
      hash_file_into(state.get(), e);
    }
  } else {
    hash_file_into(state.get(), path);
  }
  return hex128(XXH3_128bits_digest(state.get()));
}

std::string text_hash(const std::string& text) { return hex128(XXH3_128bits(text.data(), text.size())); }

std::string log_tail(const fs::path& file, std::size_t n) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  std::string out;
  for (std::size_t i = lines.size() > n ? lines.size() - n : 0; i < lines.size(); ++i) out += (out.empty() ? "" : " | ") + lines[i];
  return out;
}

}  // namespace stentsim::files
