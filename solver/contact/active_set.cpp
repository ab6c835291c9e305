#include "solver/contact/active_set.hpp"

#include "common/log.hpp"

namespace stentsim::solver::contact {

void ActiveSet::log_changes(std::string_view pair, const Changes& c) {
  if (c.entered > 0 || c.left > 0)
    log::debug("    contact '{}': {} points active (+{}, -{})", pair, c.active, c.entered, c.left);
}

}  // namespace stentsim::solver::contact
