#include "device_gen/balloon_design.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/config.hpp"
#include "common/units.hpp"

namespace stentsim::device_gen {

int BalloonDesign::around() const {
  if (elements_around > 0) return elements_around;
  const double mid_circumference = std::numbers::pi * (outer_diameter - wall_thickness);
  return std::max(3, static_cast<int>(std::lround(mid_circumference / element_size_around)));
}

int BalloonDesign::along() const {
  if (elements_along > 0) return elements_along;
  return std::max(1, static_cast<int>(std::lround(length / element_size_along)));
}

BalloonDesign parse_balloon_design(ConfigMap& section) {
  BalloonDesign d;
  d.outer_diameter = section.quantity("outer_diameter", units::kLength, d.outer_diameter, Range::positive());
  d.wall_thickness = section.quantity("wall_thickness", units::kLength, d.wall_thickness, Range::positive());
  d.length = section.quantity("length", units::kLength, d.length, Range::positive());
  d.element_size_around = section.quantity("element_size_around", units::kLength, d.element_size_around, Range::positive());
  d.element_size_along = section.quantity("element_size_along", units::kLength, d.element_size_along, Range::positive());
  d.elements_around = section.integer("elements_around", 0, Range::between(0, 100000));
  d.elements_along = section.integer("elements_along", 0, Range::between(0, 100000));
  if (d.elements_around > 0 && d.elements_around < 3) section.fail("elements_around", "needs at least 3 elements around");
  if (2.0 * d.wall_thickness >= d.outer_diameter)
    section.fail("wall_thickness", fmt::format("a wall of {} mm leaves no lumen in a balloon of outer diameter {} mm",
                                               d.wall_thickness, d.outer_diameter));
  section.finish();
  return d;
}

}  // namespace stentsim::device_gen
