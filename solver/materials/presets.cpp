#include "solver/materials/presets.hpp"

#include <stdexcept>

namespace stentsim::solver {
namespace {

FiberFamilySpec family(double k1, double k2, double angle_deg) {
  FiberFamilySpec f;
  f.law.k1 = k1;
  f.law.k2 = k2;
  f.angle_deg = angle_deg;
  return f;
}

// Artery layers (paper Section 2.1, App. B): two families at +-phi; at 0 deg
// they coincide and the fiber term counts twice (DESIGN.md §8).
Material artery_layer(const std::string& name, double young, double k1, double k2, double phi_deg, bool viscous) {
  Material m;
  m.name = name;
  m.matrix = CoupledNeoHooke::from_young_poisson(young, 0.45);
  m.fibers = {family(k1, k2, phi_deg), family(k1, k2, -phi_deg)};
  if (viscous) m.viscous = ViscousBranch{0.5, 0.3};
  return m;
}

}  // namespace

Material material_preset(const std::string& name) {
  if (name == "media") return artery_layer("media", 0.1566, 0.64e-3, 3.54, 0.0, true);
  if (name == "intima") return artery_layer("intima", 0.1566, 0.64e-3, 3.54, 0.0, true);
  if (name == "adventitia") return artery_layer("adventitia", 0.01566, 5.1e-3, 15.4, 40.0, false);
  if (name == "balloon") {
    // Paper Section 2.3: E = 17 MPa, nu = 0; longitudinal fibers (90 deg from
    // circumferential) k1 = 1000, k2 = 0.01; circumferential k1 = 1.5e-7, k2 = 0.35.
    // Viscous branch: values ours (DESIGN.md §8).
    Material m;
    m.name = "balloon";
    m.matrix = CoupledNeoHooke::from_young_poisson(17.0, 0.0);
    m.fibers = {family(1000.0, 0.01, 90.0), family(1.5e-7, 0.35, 0.0)};
    m.viscous = ViscousBranch{0.5, 0.05};
    return m;
  }
  throw std::out_of_range("unknown material preset '" + name + "'");
}

std::vector<std::string> material_preset_names() { return {"media", "adventitia", "intima", "balloon"}; }

}  // namespace stentsim::solver
