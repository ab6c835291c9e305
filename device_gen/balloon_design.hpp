#pragma once
// The simplified balloon (paper 2.3; DESIGN.md §5 Balloon): a thin tube, one
// layer of linear hex8 through the wall. All lengths in mm.
#include <numbers>

namespace stentsim {
class ConfigMap;
}

namespace stentsim::device_gen {

struct BalloonDesign {
  double outer_diameter = 0.98;
  double wall_thickness = 0.04;
  double length = 9.4;
  /// Target element sizes; the defaults give the paper's 29 x 44 = 1,276
  /// elements for 9.4 mm (mid-wall circumference / 29, 9.4 mm / 44).
  double element_size_around = std::numbers::pi * 0.94 / 29.0;
  double element_size_along = 9.4 / 44.0;
  /// Explicit counts override the sizes (0 = from size). The paper's 18 mm
  /// balloon has 35 x 79 = 2,765 elements: give these counts to match it.
  int elements_around = 0;
  int elements_along = 0;

  int around() const;
  int along() const;
  double inner_diameter() const { return outer_diameter - 2.0 * wall_thickness; }
};

/// Reads a `device.balloon` section: outer_diameter, wall_thickness, length,
/// element_size_around, element_size_along, elements_around, elements_along.
/// Calls section.finish(). Throws InputError.
BalloonDesign parse_balloon_design(ConfigMap& section);

}  // namespace stentsim::device_gen
