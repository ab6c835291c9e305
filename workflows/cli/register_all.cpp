#include "workflows/cli/commands.hpp"

namespace stentsim::cli {

void register_version(CLI::App& app);

void register_all(CLI::App& app) { register_version(app); }

}  // namespace stentsim::cli
