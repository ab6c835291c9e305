#include "solver/app/contact/registry.hpp"

namespace stentsim::solver {

const std::vector<ContactKind>& contact_kinds() {
  static const std::vector<ContactKind> kinds{beam_to_surface_contact(), surface_to_surface_contact()};
  return kinds;
}

}  // namespace stentsim::solver
