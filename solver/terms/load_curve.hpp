#pragma once
// Piecewise-linear load curve in pseudo-time; constant beyond its ends.
#include <string>
#include <utility>
#include <vector>

namespace stentsim::solver {

class LoadCurve {
 public:
  LoadCurve() = default;  // the constant 1
  /// Points (time, factor), times strictly increasing. Throws std::invalid_argument otherwise.
  explicit LoadCurve(std::vector<std::pair<double, double>> points);
  static LoadCurve constant(double value) { return LoadCurve({{0.0, value}}); }
  static LoadCurve ramp(double t0, double t1) { return LoadCurve({{t0, 0.0}, {t1, 1.0}}); }
  double operator()(double t) const;
  const std::vector<std::pair<double, double>>& points() const { return points_; }

 private:
  std::vector<std::pair<double, double>> points_{{0.0, 1.0}};
};

}  // namespace stentsim::solver
