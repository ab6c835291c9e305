// `stentsim version`: the tool and library versions (for bug reports).
#include <cstdio>

#include "workflows/cli/commands.hpp"
#include "workflows/version.hpp"

namespace stentsim::cli {

void register_version(CLI::App& app) {
  auto* sub = app.add_subcommand("version", "Print the stentsim version");
  on(sub, [] {
    std::printf("stentsim %s\n", kVersion);
    return 0;
  });
}

}  // namespace stentsim::cli
