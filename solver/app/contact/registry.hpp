#pragma once
// The contact pair kinds, one factory per file; registry.cpp lists them.
#include "solver/io/scene_kinds.hpp"

namespace stentsim::solver {

ContactKind beam_to_surface_contact();
ContactKind surface_to_surface_contact();

}  // namespace stentsim::solver
