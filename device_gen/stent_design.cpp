#include "device_gen/stent_design.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "common/config.hpp"
#include "common/units.hpp"

namespace stentsim::device_gen {

const char* to_string(ConnectorShape s) { return s == ConnectorShape::axial ? "axial" : "peak-to-valley"; }

double StentDesign::strut_length() const {
  const double half_crown_distance = std::numbers::pi * crimped_diameter / (2.0 * crowns);
  return std::hypot(crown_height, half_crown_distance);
}

int StentDesign::members() const { return rings * 2 * crowns + (rings - 1) * connectors_per_gap; }

int StentDesign::beam_elements() const {
  return rings * 2 * crowns * elements_per_strut + (rings - 1) * connectors_per_gap * elements_per_connector;
}

StentDesign parse_stent_design(ConfigMap& section) {
  StentDesign d;
  d.crowns = section.integer("crowns", d.crowns, Range::between(3, 64));
  d.crimped_diameter = section.quantity("crimped_diameter", units::kLength, d.crimped_diameter, Range::positive());
  d.crown_height = section.quantity("crown_height", units::kLength, d.crown_height, Range::positive());
  d.ring_pitch = section.quantity("ring_pitch", units::kLength, d.ring_pitch, Range::positive());
  d.strut_radius = section.quantity("strut_radius", units::kLength, d.strut_radius, Range::positive());
  d.elements_per_strut = section.integer("elements_per_strut", d.elements_per_strut, Range::between(1, 50));
  d.elements_per_connector = section.integer("elements_per_connector", d.elements_per_connector, Range::between(1, 50));
  d.connectors_per_gap = section.integer("connectors_per_gap", d.connectors_per_gap, Range::between(1, 64));
  d.connector_shape = section.choice("connector_shape", {"peak-to-valley", "axial"}, std::string("peak-to-valley")) == "axial"
                          ? ConnectorShape::axial
                          : ConnectorShape::peak_to_valley;
  if (section.has("rings") && section.has("length"))
    section.fail("length", "give either `rings` or `length`, not both");
  if (section.has("length")) {
    const double length = section.quantity("length", units::kLength, std::nullopt, Range::positive());
    const double rings = 1.0 + std::round((length - d.crown_height) / d.ring_pitch);
    if (rings < 1.0)
      section.fail("length", fmt::format("a stent of {} mm is shorter than one ring ({} mm)", length, d.crown_height));
    d.rings = static_cast<int>(rings);
  } else {
    d.rings = section.integer("rings", d.rings, Range::between(1, 200));
  }
  if (d.crowns % d.connectors_per_gap != 0)
    section.fail("connectors_per_gap", fmt::format("must divide the number of crowns ({}) so that connectors are evenly spread",
                                                   d.crowns));
  if (d.ring_pitch < d.crown_height - 1e-12 && d.connector_shape == ConnectorShape::peak_to_valley)
    section.fail("ring_pitch", fmt::format("a ring pitch ({} mm) below the crown height ({} mm) makes rings overlap",
                                           d.ring_pitch, d.crown_height));
  section.finish();
  return d;
}

}  // namespace stentsim::device_gen
