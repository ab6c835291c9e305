#include "solver/app/qoi/registry.hpp"

namespace stentsim::solver {

const std::vector<QoiKind>& qoi_kinds() {
  static const std::vector<QoiKind> kinds{mean_radius_qoi(), max_displacement_qoi(), tip_position_qoi(),
                                          tip_rotation_angle_qoi(), ring_expansion_qoi(),
                                          stent_expansion_qoi(), balloon_profile_qoi(), layer_stresses_qoi(),
                                          malapposition_qoi(), lumen_area_qoi()};
  return kinds;
}

}  // namespace stentsim::solver
