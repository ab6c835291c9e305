#pragma once
// The paper's materials as named presets (DESIGN.md §5, §8), in MPa and s.
#include <string>
#include <vector>

#include "solver/materials/material.hpp"

namespace stentsim::solver {

/// "media", "adventitia", "intima", "balloon". Throws std::out_of_range for other names.
Material material_preset(const std::string& name);
std::vector<std::string> material_preset_names();

}  // namespace stentsim::solver
