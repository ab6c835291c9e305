#include "device_gen/centerline_input.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/error.hpp"

namespace stentsim::device_gen {

std::size_t Centerline::segment(double s, double& t) const {
  s = std::clamp(s, begin(), end());
  auto it = std::upper_bound(abscissa.begin(), abscissa.end(), s);
  std::size_t i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - abscissa.begin() - 1, 0));
  i = std::min(i, abscissa.size() - 2);
  t = (s - abscissa[i]) / (abscissa[i + 1] - abscissa[i]);
  return i;
}

Eigen::Vector3d Centerline::point_at(double s) const {
  double t;
  const std::size_t i = segment(s, t);
  return (1 - t) * points[i] + t * points[i + 1];
}

double Centerline::radius_at(double s) const {
  double t;
  const std::size_t i = segment(s, t);
  return (1 - t) * radius[i] + t * radius[i + 1];
}

Eigen::Vector3d Centerline::normal_at(double s) const {
  double t;
  const std::size_t i = segment(s, t);
  return (1 - t) * normals[i] + t * normals[i + 1];
}

double Centerline::smoothed_radius(double s, double window) const {
  const double a = std::max(begin(), s - 0.5 * window), b = std::min(end(), s + 0.5 * window);
  if (b - a <= 0) return radius_at(s);
  // Exact integral of the piecewise-linear radius over [a, b].
  double integral = 0;
  double prev_s = a, prev_r = radius_at(a);
  for (std::size_t i = 0; i < abscissa.size(); ++i) {
    if (abscissa[i] <= a) continue;
    if (abscissa[i] >= b) break;
    integral += 0.5 * (prev_r + radius[i]) * (abscissa[i] - prev_s);
    prev_s = abscissa[i];
    prev_r = radius[i];
  }
  integral += 0.5 * (prev_r + radius_at(b)) * (b - prev_s);
  return integral / (b - a);
}

Centerline centerline_from_mesh(const MeshData& m, const std::string& source) {
  Centerline c;
  c.source = source;
  std::vector<std::int64_t> ids;
  if (m.num_cells() == 1 && (m.cell_types[0] == CellType::polyline || m.cell_types[0] == CellType::line)) {
    ids = m.cell(0);
  } else {
    throw InputError(fmt::format("{}: expected a single polyline (the centerline), found {} cells", source, m.num_cells()));
  }
  if (ids.size() < 4) throw InputError(fmt::format("{}: the centerline has {} points; at least 4 are needed", source, ids.size()));
  auto array = [&](const char* name, int components) -> const DataArray& {
    auto it = m.point_data.find(name);
    if (it == m.point_data.end())
      throw InputError(fmt::format("{}: point array '{}' is missing (expected VMTK centerline arrays)", source, name));
    if (it->second.components != components || it->second.tuples() != m.points.size())
      throw InputError(fmt::format("{}: point array '{}' must have {} component(s) per point", source, name, components));
    return it->second;
  };
  const DataArray& r = array("MaximumInscribedSphereRadius", 1);
  const DataArray& s = array("Abscissas", 1);
  const DataArray& n = array("ParallelTransportNormals", 3);
  for (std::int64_t id : ids) {
    const auto i = static_cast<std::size_t>(id);
    c.points.push_back(m.points[i]);
    c.abscissa.push_back(s.at(i));
    c.radius.push_back(r.at(i));
    c.normals.emplace_back(n.at(i, 0), n.at(i, 1), n.at(i, 2));
    if (!(c.radius.back() > 0) || !std::isfinite(c.radius.back()))
      throw InputError(fmt::format("{}: MaximumInscribedSphereRadius at point {} is {} (expected > 0)", source, id, c.radius.back()));
  }
  for (std::size_t i = 1; i < c.abscissa.size(); ++i)
    if (!(c.abscissa[i] > c.abscissa[i - 1]))
      throw InputError(fmt::format("{}: Abscissas must increase strictly along the polyline (point {}: {} after {})", source,
                                   ids[i], c.abscissa[i], c.abscissa[i - 1]));
  return c;
}

Centerline read_centerline(const std::filesystem::path& file) { return centerline_from_mesh(read_vtp(file.string()), file.string()); }

}  // namespace stentsim::device_gen
