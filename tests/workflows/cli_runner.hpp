#pragma once
// Runs the stentsim binary under test and captures its output and exit code.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
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

/// Phantom -> centerline -> wall mesh through the binary, into `dir` (emptied
/// first): dir/{lumen,wall,centerline}.vtp and dir/mesh/artery.vtu. Returns the
/// first failing step's result, or the mesh step's.
inline CliResult mesh_phantom(const std::string& preset, const std::filesystem::path& dir, const std::string& mesh_args) {
  std::filesystem::remove_all(dir);
  auto r = run_stentsim("phantom --preset " + preset + " --out " + dir.string());
  if (r.code != 0) return r;
  r = run_stentsim("centerline --lumen " + (dir / "lumen.vtp").string() + " --out " + (dir / "centerline.vtp").string());
  if (r.code != 0) return r;
  return run_stentsim("mesh --lumen " + (dir / "lumen.vtp").string() + " --wall " + (dir / "wall.vtp").string() +
                      " --centerline " + (dir / "centerline.vtp").string() + " --out " + (dir / "mesh").string() + " " +
                      mesh_args);
}

}  // namespace stentsim::testing
