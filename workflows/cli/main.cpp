// stentsim: the command-line entry point. Each sub-command lives in its own
// file (cli/cmd_*.cpp) and registers itself here.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

#include "common/error.hpp"
#include "common/heap_policy.hpp"
#include "workflows/cli/commands.hpp"
#include "workflows/version.hpp"

int main(int argc, char** argv) {
  stentsim::heap::keep_large_blocks();  // factorizations reuse freed pages (common/heap_policy.hpp)
  CLI::App app{"stentsim: patient-specific simulation of balloon angioplasty with stent implantation"};
  app.set_version_flag("--version", std::string(stentsim::kVersion));
  app.require_subcommand(1);
  stentsim::cli::register_all(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    return stentsim::cli::dispatch(app);
  } catch (const stentsim::Interrupted&) {
    std::fprintf(stderr, "interrupted\n");
    return 130;
  } catch (const stentsim::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", stentsim::describe_unexpected(e).c_str());
    return 1;
  } catch (...) {
    std::fprintf(stderr, "error: %s\n", stentsim::describe_unknown().c_str());
    return 1;
  }
}
