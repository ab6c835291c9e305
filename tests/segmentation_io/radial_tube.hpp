#pragma once
// Test lumens: an open tube along z whose radius about the z axis is r(z, θ).
#include <cmath>
#include <functional>
#include <numbers>

#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::testing {

/// `rings` + 1 rings of `around` points from z = 0 to `length`, outward normals.
inline segmentation::TriSurface radial_tube(double length, const std::function<double(double, double)>& r,
                                            int rings = 200, int around = 96) {
  segmentation::TriSurface t;
  for (int k = 0; k <= rings; ++k) {
    const double z = length * k / rings;
    for (int j = 0; j < around; ++j) {
      const double a = 2 * std::numbers::pi * j / around, rr = r(z, a);
      t.points.emplace_back(rr * std::cos(a), rr * std::sin(a), z);
    }
  }
  for (int k = 0; k < rings; ++k)
    for (int j = 0; j < around; ++j) {
      const int a = k * around + j, b = k * around + (j + 1) % around, c = a + around, d = b + around;
      t.triangles.push_back({a, b, d});
      t.triangles.push_back({a, d, c});
    }
  return t;
}

}  // namespace stentsim::testing
