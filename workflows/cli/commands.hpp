#pragma once
// Registry of the CLI's sub-commands. A command adds itself with a
// registration function and a handler that runs when it was chosen.
#include <CLI/CLI.hpp>

#include <functional>

namespace stentsim::cli {

/// A command's handler; returns the process exit code.
using Handler = std::function<int()>;

/// Adds every sub-command to `app`.
void register_all(CLI::App& app);
/// Runs the handler of the sub-command that was parsed.
int dispatch(CLI::App& app);
/// Used by command files: remember `handler` for sub-command `sub`.
void on(CLI::App* sub, Handler handler);

}  // namespace stentsim::cli
