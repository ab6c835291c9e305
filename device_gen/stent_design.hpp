#pragma once
// The corrugated-ring stent with straight connectors (paper 2.2, Fig. 3;
// DESIGN.md §5 Stent, §8 connector shape and joints). All lengths in mm.
#include <string>

namespace stentsim {
class ConfigMap;
}

namespace stentsim::device_gen {

enum class ConnectorShape {
  peak_to_valley,  // crown of ring i to the neighbouring valley of ring i+1 (default, DESIGN §8)
  axial,           // crown of ring i to the same crown of ring i+1 (peak to peak)
};
const char* to_string(ConnectorShape s);

struct StentDesign {
  int crowns = 8;                  // per ring; 2 * crowns struts per ring
  int rings = 4;                   // from `length` when that is given
  double crimped_diameter = 1.15;  // of the strut centerlines
  double crown_height = 1.5;       // axial extent of a strut
  double ring_pitch = 1.5;         // axial distance of adjacent rings
  double strut_radius = 0.06;      // circular section (thickness 0.12 mm)
  int elements_per_strut = 3;
  int elements_per_connector = 3;
  int connectors_per_gap = 2;      // between adjacent rings
  ConnectorShape connector_shape = ConnectorShape::peak_to_valley;
  int material_id = 0;             // the stent material of the scene (solver preset, DESIGN §8)

  /// Axial length of the stent: (rings - 1) * pitch + crown height.
  double length() const { return (rings - 1) * ring_pitch + crown_height; }
  /// Outer envelope of the crimped stent (1.27 mm by default), checked against the lumen.
  double envelope_diameter() const { return crimped_diameter + 2.0 * strut_radius; }
  /// Length of one strut on the crimped cylinder (a helix: axial crown height,
  /// circumferential half a crown distance): 1.5169 mm by default.
  double strut_length() const;
  /// Beam elements, nodes and nodal DOFs before joint coupling (9 per Hermite
  /// end node, 3 per middle node): 210 / 490 / 3,150 for 4 rings.
  int beam_elements() const;
  int members() const;
};

/// Reads a `device.stent` section: crowns, rings | length (rings from
/// length: 1 + round((length - crown_height) / ring_pitch)), crimped_diameter,
/// crown_height, ring_pitch, strut_radius, elements_per_strut,
/// elements_per_connector, connectors_per_gap, connector_shape
/// (peak-to-valley | axial). Calls section.finish(). Throws InputError.
StentDesign parse_stent_design(ConfigMap& section);

}  // namespace stentsim::device_gen
