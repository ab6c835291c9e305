#pragma once
// A space curve c(u) = (x(u), y(u), z(u)) from three FITPACK splines on the
// same parameter (here: centerline arc length, DESIGN.md §5 Placement).
#include <Eigen/Core>

#include "device_gen/fitpack/bspline.hpp"

namespace stentsim::device_gen {

struct SplineCurve {
  fitpack::BSpline x, y, z;

  double begin() const { return x.begin(); }
  double end() const { return x.end(); }
  Eigen::Vector3d position(double u) const { return {x(u), y(u), z(u)}; }
  Eigen::Vector3d derivative(double u, int order) const {
    return {x.evaluate(u, order), y.evaluate(u, order), z.evaluate(u, order)};
  }
};

}  // namespace stentsim::device_gen
