#include "workflows/cli/commands.hpp"

#include <map>

namespace stentsim::cli {
namespace {
std::map<CLI::App*, Handler>& handlers() {
  static std::map<CLI::App*, Handler> h;
  return h;
}
}  // namespace

void on(CLI::App* sub, Handler handler) { handlers()[sub] = std::move(handler); }

int dispatch(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands()) {
    auto it = handlers().find(sub);
    if (it != handlers().end()) return it->second();
    if (!sub->get_subcommands().empty()) return dispatch(*sub);  // e.g. `cohort run`
  }
  return 2;
}

}  // namespace stentsim::cli
