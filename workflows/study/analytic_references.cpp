#include "workflows/study/analytic_references.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/units.hpp"
#include "workflows/study/references/tube_reference.hpp"

namespace stentsim::study {
namespace {

[[noreturn]] void bad(const StudyConfig& s, const std::string& what) {
  throw InputError(fmt::format("{}: reference: {} (in the base file {})", s.file.string(), what, s.base_file.string()));
}

ConfigMap at(const StudyConfig& s, const YAML::Node& input, const std::string& dotted) {
  const YAML::Node n = get_dotted(input, dotted);
  if (!n.IsDefined() || !n.IsMap()) bad(s, fmt::format("the run's input has no map '{}'", dotted));
  return ConfigMap(n, std::make_shared<const std::filesystem::path>(s.base_file), dotted);
}

// The list entry of `list_key` whose `field` equals `value`.
ConfigMap entry(const StudyConfig& s, const YAML::Node& input, const std::string& list_key, const std::string& field,
                const std::string& value) {
  const YAML::Node list = input[list_key];
  if (list && list.IsSequence())
    for (std::size_t i = 0; i < list.size(); ++i)
      if (list[i][field] && list[i][field].as<std::string>() == value) return at(s, input, fmt::format("{}.{}", list_key, i));
  bad(s, fmt::format("no entry of '{}' has {}: {}", list_key, field, value));
}

// Load-curve factor at time t (piecewise linear, held constant outside).
double curve_at(const StudyConfig& s, const YAML::Node& input, const YAML::Node& cond, double t) {
  if (!cond["curve"]) return 1.0;
  const std::string name = cond["curve"].as<std::string>();
  const YAML::Node pts = input["load_curves"][name];
  if (!pts || !pts.IsSequence() || pts.size() == 0) bad(s, fmt::format("load curve '{}' not found", name));
  std::vector<std::pair<double, double>> p;
  for (const auto& q : pts) p.emplace_back(q[0].as<double>(), q[1].as<double>());
  if (t <= p.front().first) return p.front().second;
  for (std::size_t i = 1; i < p.size(); ++i)
    if (t <= p[i].first) return p[i - 1].second + (p[i].second - p[i - 1].second) * (t - p[i - 1].first) / (p[i].first - p[i - 1].first);
  return p.back().second;
}

double qoi_time(const StudyConfig& s, const YAML::Node& input) {
  auto q = entry(s, input, "qoi", "name", s.qoi);
  if (q.node()["time"]) return q.number("time");
  const YAML::Node end = get_dotted(input, "solver.time.end");
  if (!end.IsDefined()) bad(s, "neither qoi.time nor solver.time.end is given");
  return end.as<double>();
}

std::vector<double> tube(const StudyConfig& s, const YAML::Node& input) {
  auto g = at(s, input, "bodies.0.mesh.generate");
  if (g.string("type") != "ring_sector") bad(s, "tube_plane_strain needs bodies.0.mesh.generate.type: ring_sector");
  const double a = g.quantity("inner_radius", units::kLength), b = g.quantity("outer_radius", units::kLength);
  auto nh = at(s, input, "bodies.0.materials.0.neo_hooke");
  const double E = nh.quantity("E", units::kPressure), nu = nh.number("nu");
  // The pressure condition on the tube and its load factor at the QoI's time.
  const YAML::Node conds = input["conditions"];
  for (std::size_t i = 0; conds && i < conds.size(); ++i) {
    if (!conds[i]["type"] || conds[i]["type"].as<std::string>() != "pressure") continue;
    auto c = at(s, input, fmt::format("conditions.{}", i));
    const double p = c.quantity("value", units::kPressure) * curve_at(s, input, conds[i], qoi_time(s, input));
    try {
      return {reference::PlaneStrainTube::from_young(E, nu, a, b).inner_radius(p)};
    } catch (const std::exception& e) {
      bad(s, fmt::format("the tube reference has no solution at p = {} MPa: {}", p, e.what()));
    }
  }
  bad(s, "no condition of type pressure");
}

Eigen::Vector3d vec(const YAML::Node& n) {
  if (!n || !n.IsSequence() || n.size() != 3) throw std::invalid_argument("expected [x, y, z]");
  return {n[0].as<double>(), n[1].as<double>(), n[2].as<double>()};
}

std::vector<double> rollup(const StudyConfig& s, const YAML::Node& input) {
  auto g = at(s, input, "bodies.0.beam.generate");
  if (g.string("type") != "line") bad(s, "beam_rollup needs bodies.0.beam.generate.type: line");
  const Eigen::Vector3d a = vec(g.node()["start"]), b = vec(g.node()["end"]);
  const double L = (b - a).norm();
  const Eigen::Vector3d e1 = (b - a) / L;
  Eigen::Vector3d d2 = g.node()["d2"] ? vec(g.node()["d2"]) : Eigen::Vector3d::UnitY();
  d2 = (d2 - d2.dot(e1) * e1).normalized();
  const Eigen::Vector3d d3 = e1.cross(d2);
  auto beam = at(s, input, "bodies.0.beam");
  const double E = beam.quantity("E", units::kPressure);
  auto sec = at(s, input, "bodies.0.beam.section");
  const YAML::Node conds = input["conditions"];
  for (std::size_t i = 0; conds && i < conds.size(); ++i) {
    if (!conds[i]["type"] || conds[i]["type"].as<std::string>() != "point_moment") continue;
    const Eigen::Vector3d m = vec(conds[i]["value"]) * curve_at(s, input, conds[i], qoi_time(s, input));
    const double M = m.norm();
    if (M == 0) bad(s, "the end moment is zero");
    const Eigen::Vector3d mh = m / M;
    double I = 0;
    if (std::abs(std::abs(mh.dot(d3)) - 1) < 1e-9) I = sec.number("I3");
    else if (std::abs(std::abs(mh.dot(d2)) - 1) < 1e-9) I = sec.number("I2");
    else bad(s, "beam_rollup needs the end moment along a principal axis of the section (d2 or d1 x d2)");
    const double kappa = M / (E * I), theta = kappa * L;
    if (s.qoi == "tip_rotation_angle" || entry(s, input, "qoi", "name", s.qoi).string("type") == "tip_rotation_angle")
      return {theta};
    const Eigen::Vector3d e2 = mh.cross(e1);
    const Eigen::Vector3d tip = a + (std::sin(theta) * e1 + (1 - std::cos(theta)) * e2) / kappa;
    return {tip.x(), tip.y(), tip.z()};
  }
  bad(s, "no condition of type point_moment");
}

}  // namespace

std::vector<double> analytic_reference(const StudyConfig& study, const YAML::Node& input) {
  try {
    switch (study.reference.type) {
      case Reference::Type::tube_plane_strain: return tube(study, input);
      case Reference::Type::beam_rollup: return rollup(study, input);
      case Reference::Type::value: return study.reference.value;
      default: return {};
    }
  } catch (const YAML::Exception& e) {
    bad(study, fmt::format("cannot read the run's input: {}", e.what()));
  } catch (const std::invalid_argument& e) {
    bad(study, e.what());
  }
}

}  // namespace stentsim::study
