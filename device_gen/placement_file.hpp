#pragma once
// placement.yaml and balloon_centerline.vtp (DESIGN.md §1, §8).
//
// placement.yaml (format: stentsim-placement-1, units mm) holds everything
// needed to rebuild the balloon centerline with any FITPACK, e.g.
//   scipy.interpolate.UnivariateSpline(fit.abscissae, fit.points.x,
//                                      w=fit.weights, k=3, s=fit.smoothing)
// for each coordinate (abscissae are measured from the balloon's proximal
// end), plus the resulting knots and B-spline coefficients (FITPACK layout:
// n knots, n-4 coefficients; splev evaluates them), residuals, the site, the
// ends, the envelope and the clearance. frame.initial_normal starts the
// rotation-minimizing frame at the proximal end.
//
// balloon_centerline.vtp: one polyline along the device axis sampled every
// ~0.05 mm over the balloon length, point data Abscissas (arc length from the
// proximal end), Tangents, ParallelTransportNormals (rotation-minimizing),
// Curvature (1/mm).
#include <filesystem>

#include "common/mesh_data.hpp"
#include "device_gen/device_axis.hpp"
#include "device_gen/placement.hpp"

namespace stentsim::device_gen {

void write_placement_yaml(const Placement& placement, const std::filesystem::path& file);
/// Reads placement.yaml. Throws InputError naming the file and the key.
Placement read_placement_yaml(const std::filesystem::path& file);
/// The device axis of a placement: along the fitted spline, centred at the
/// site, as long as the balloon.
DeviceAxis axis_from_placement(const Placement& placement);
/// The axis as a polyline with VMTK-like arrays.
MeshData axis_polyline(const DeviceAxis& axis, double step = 0.05);

}  // namespace stentsim::device_gen
