#include "solver/beams/section.hpp"

#include "common/error.hpp"

#include <cmath>
#include <numbers>

namespace stentsim::solver::beams {

BeamSection BeamSection::circular(double E, double G, double R, double shear_factor) {
  const double pi = std::numbers::pi;
  const double A = pi * R * R;
  const double I = pi * R * R * R * R / 4.0;
  BeamSection s = from_values(E, G, A, shear_factor * A, shear_factor * A, I, I, 2.0 * I);
  s.radius = R;
  return s;
}

BeamSection BeamSection::circular_plastic(const PlasticBendingLaw& law, double shear_factor) {
  law.validate("plastic beam section");
  BeamSection s = circular(law.E, law.G, law.radius, shear_factor);
  s.plastic = law;
  return s;
}

BeamSection BeamSection::from_values(double E, double G, double A, double A2, double A3, double I2, double I3,
                                     double IT) {
  BeamSection s;
  s.CF = {E * A, G * A2, G * A3};
  s.CM = {G * IT, E * I2, E * I3};
  s.area = A;
  s.bending_inertia = I2;
  return s;
}

void BeamSection::validate(const std::string& where) const {
  const char* names[6] = {"EA", "GA2", "GA3", "GIT", "EI2", "EI3"};
  for (int i = 0; i < 6; ++i) {
    const double v = i < 3 ? CF[i] : CM[i - 3];
    if (!(std::isfinite(v) && v > 0.0))
      throw InputError(where + ": beam section stiffness " + names[i] + " must be positive and finite, got " +
                       std::to_string(v));
  }
}

}  // namespace stentsim::solver::beams
