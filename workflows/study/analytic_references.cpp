#include "workflows/study/analytic_references.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <stdexcept>

#include "common/config.hpp"
#include "common/error.hpp"
#include "common/units.hpp"
#include "solver/beams/plastic_bending.hpp"
#include "workflows/study/references/plastic_moment_curvature.hpp"
#include "workflows/study/references/rod_shooting.hpp"
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

// The QoI entry's type (tip_position, tip_rotation_angle, ...).
std::string qoi_type(const StudyConfig& s, const YAML::Node& input) { return entry(s, input, "qoi", "name", s.qoi).string("type"); }

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
  if (beam.has("plastic") || beam.has("material"))
    bad(s, "beam_rollup is the elastic closed form; this beam is elasto-plastic (bodies.0.beam.plastic or material): use "
           "reference type beam_plastic_rollup");
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
    if (qoi_type(s, input) == "tip_rotation_angle") return {theta};
    const Eigen::Vector3d e2 = mh.cross(e1);
    const Eigen::Vector3d tip = a + (std::sin(theta) * e1 + (1 - std::cos(theta)) * e2) / kappa;
    return {tip.x(), tip.y(), tip.z()};
  }
  bad(s, "no condition of type point_moment");
}

// The beam load case of the shooting and plastic references: body 0 clamped
// (position and rotation) at its first node, one dead load of `load_type` at
// its last node, nothing else. Returns the load's condition index.
std::size_t cantilever_load(const StudyConfig& s, const YAML::Node& input, const std::string& kind, const std::string& load_type) {
  const std::string body = at(s, input, "bodies.0").string("name");
  const YAML::Node conds = input["conditions"];
  std::optional<std::size_t> load;
  bool clamped = false;
  for (std::size_t i = 0; conds && i < conds.size(); ++i) {
    auto c = at(s, input, fmt::format("conditions.{}", i));
    const std::string type = c.string("type"), node = c.has("node") ? c.string("node") : "";
    const std::string what = fmt::format("conditions.{} ({} on {}, node {})", i, type, c.has("body") ? c.string("body") : "?", node);
    if (!c.has("body") || c.string("body") != body) bad(s, fmt::format("{} covers one beam body '{}'; {} is not on it", kind, body, what));
    if (type == "clamp" && node == "first") {
      if (c.has("fix")) {
        const std::string fix = c.string("fix");
        if (fix.find("position") == std::string::npos || fix.find("rotation") == std::string::npos)
          bad(s, fmt::format("{} needs the first node clamped in position and rotation; {} fixes '{}'", kind, what, fix));
      }
      clamped = true;
    } else if (type == load_type && node == "last" && !load) {
      load = i;
    } else {
      bad(s, fmt::format("{} covers a clamp at node first and one {} at node last; {} is not covered", kind, load_type, what));
    }
  }
  if (!clamped) bad(s, fmt::format("{} needs a condition of type clamp at node first (conditions)", kind));
  if (!load) bad(s, fmt::format("{} needs a condition of type {} at node last (conditions)", kind, load_type));
  return *load;
}

// Time of the run's start (the load path starts there).
double start_time(const YAML::Node& input) {
  const YAML::Node t0 = get_dotted(input, "solver.time.start");
  return t0.IsDefined() ? t0.as<double>() : 0.0;
}

// The largest load factor on [t0, t] and the factor at t; a negative factor
// (reverse loading) is refused: the closed form covers one load direction.
std::pair<double, double> curve_path(const StudyConfig& s, const YAML::Node& input, const YAML::Node& cond, double t0, double t,
                                     const std::string& kind) {
  std::vector<double> ts{t0, t};
  if (cond["curve"])
    for (const auto& q : input["load_curves"][cond["curve"].as<std::string>()])
      if (q[0].as<double>() > t0 && q[0].as<double>() < t) ts.push_back(q[0].as<double>());
  double mx = 0;
  for (double x : ts) {
    const double f = curve_at(s, input, cond, x);
    if (f < 0) bad(s, fmt::format("{}: the load curve is negative ({}) at t = {}; the closed form covers loading and unloading in "
                                  "one direction only", kind, f, x));
    mx = std::max(mx, f);
  }
  return {mx, curve_at(s, input, cond, t)};
}

// Tip of a straight cantilever from `start` along e1 bent into an arc of
// curvature kappa about the unit moment axis mh.
Eigen::Vector3d arc_tip(const Eigen::Vector3d& start, const Eigen::Vector3d& e1, const Eigen::Vector3d& mh, double kappa, double L) {
  if (kappa == 0) return start + L * e1;
  const Eigen::Vector3d e2 = mh.cross(e1);
  const double theta = kappa * L;
  return start + (std::sin(theta) * e1 + (1 - std::cos(theta)) * e2) / kappa;
}

// beam_plastic_rollup: the end-moment cantilever with the App. C section law;
// its curvature is the closed-form moment-curvature path at the QoI's time.
std::vector<double> plastic_rollup(const StudyConfig& s, const YAML::Node& input) {
  const std::string kind = "beam_plastic_rollup";
  auto g = at(s, input, "bodies.0.beam.generate");
  if (g.string("type") != "line") bad(s, kind + " needs bodies.0.beam.generate.type: line");
  const Eigen::Vector3d a = vec(g.node()["start"]), b = vec(g.node()["end"]);
  const double L = (b - a).norm();
  const Eigen::Vector3d e1 = (b - a) / L;
  auto beam = at(s, input, "bodies.0.beam");
  double E = 0, E_ep = 0, M_y0 = 0;
  if (beam.has("material")) {
    if (beam.string("material") != "stent") bad(s, kind + ": bodies.0.beam.material: only 'stent' is known");
    const auto law = solver::beams::PlasticBendingLaw::stent_preset();
    E = law.E, E_ep = law.E_ep, M_y0 = law.M_y0;
  } else if (beam.has("plastic")) {
    E = beam.quantity("E", units::kPressure);
    auto p = at(s, input, "bodies.0.beam.plastic");
    E_ep = p.quantity("E_ep", units::kPressure), M_y0 = p.number("M_y0");
  } else {
    bad(s, kind + " needs an elasto-plastic beam (bodies.0.beam.material: stent or bodies.0.beam.plastic); for an elastic "
                  "beam use beam_rollup");
  }
  auto sec = at(s, input, "bodies.0.beam.section");
  if (!sec.has("radius")) bad(s, kind + " needs a circular section (bodies.0.beam.section.radius)");
  const double R = sec.quantity("radius", units::kLength);
  const reference::PlasticMomentCurvature law(E, E_ep, M_y0, std::numbers::pi * R * R * R * R / 4);
  const std::size_t i = cantilever_load(s, input, kind, "point_moment");
  const YAML::Node cond = input["conditions"][i];
  const Eigen::Vector3d m = vec(cond["value"]);
  const double M = m.norm();
  if (M == 0) bad(s, kind + ": the end moment is zero");
  const Eigen::Vector3d mh = m / M;
  if (std::abs(mh.dot(e1)) > 1e-9) bad(s, kind + " needs the end moment perpendicular to the beam (pure bending, no torsion)");
  const auto [f_max, f] = curve_path(s, input, cond, start_time(input), qoi_time(s, input), kind);
  const double kappa = law.curvature(M * f, M * f_max);
  const std::string type = qoi_type(s, input);
  if (type == "tip_rotation_angle") return {kappa * L};
  if (type != "tip_position") bad(s, fmt::format("{} gives tip_position or tip_rotation_angle, not '{}'", kind, type));
  const Eigen::Vector3d tip = arc_tip(a, e1, mh, kappa, L);
  return {tip.x(), tip.y(), tip.z()};
}

// beam_shooting: the rod equations of a generated arc or line under a dead
// tip force, solved by shooting (references/rod_shooting.hpp) with the run's
// own geometry, section and load at the QoI's time.
std::vector<double> shooting(const StudyConfig& s, const YAML::Node& input) {
  const std::string kind = "beam_shooting";
  auto beam = at(s, input, "bodies.0.beam");
  if (beam.has("plastic") || beam.has("material")) bad(s, kind + " is the elastic rod; this beam is elasto-plastic");
  const double E = beam.quantity("E", units::kPressure), G = beam.quantity("G", units::kPressure);
  auto sec = at(s, input, "bodies.0.beam.section");
  reference::RodProblem p;
  if (sec.has("radius")) {
    // As the solver reads a circular section: A = pi R^2, shear areas k A, I = pi R^4 / 4, I_T = 2 I.
    const double R = sec.quantity("radius", units::kLength), k = sec.has("shear_factor") ? sec.number("shear_factor") : 6.0 / 7.0;
    const double A = std::numbers::pi * R * R, I = std::numbers::pi * R * R * R * R / 4;
    p.CF = {E * A, G * k * A, G * k * A};
    p.CM = {G * 2 * I, E * I, E * I};
  } else {
    const double A = sec.number("A");
    p.CF = {E * A, G * (sec.has("A2") ? sec.number("A2") : A), G * (sec.has("A3") ? sec.number("A3") : A)};
    p.CM = {G * sec.number("IT"), E * sec.number("I2"), E * sec.number("I3")};
  }
  auto g = at(s, input, "bodies.0.beam.generate");
  const std::string type = g.string("type");
  Eigen::Matrix3d T;
  if (type == "arc") {
    // The scene's arc: radial(s) = cos(s/R) e_r + sin(s/R) e_t, triad (n x radial, radial, -n):
    // it turns about n at 1/R, so the material reference curvature is (0, 0, -1/R).
    const Eigen::Vector3d c = vec(g.node()["center"]), a = vec(g.node()["start"]);
    const Eigen::Vector3d n = vec(g.node()["normal"]).normalized();
    const double R = (a - c).norm();
    const Eigen::Vector3d e_r = (a - c) / R;
    p.length = R * g.number("angle_deg") * std::numbers::pi / 180.0;
    p.K0 = {0, 0, -1.0 / R};
    p.r0 = a;
    const Eigen::Vector3d d1 = n.cross(e_r);
    T << d1, e_r, d1.cross(e_r);
  } else if (type == "line") {
    const Eigen::Vector3d a = vec(g.node()["start"]), b = vec(g.node()["end"]);
    p.length = (b - a).norm();
    const Eigen::Vector3d d1 = (b - a) / p.length;
    Eigen::Vector3d hint;
    if (g.node()["d2"]) hint = vec(g.node()["d2"]);
    else {  // as the scene: the global axis least aligned with the beam
      Eigen::Index k;
      d1.cwiseAbs().minCoeff(&k);
      hint = Eigen::Vector3d::Unit(k);
    }
    const Eigen::Vector3d d2 = (hint - hint.dot(d1) * d1).normalized();
    p.K0.setZero();
    p.r0 = a;
    T << d1, d2, d1.cross(d2);
  } else {
    bad(s, kind + ": bodies.0.beam.generate.type must be arc or line");
  }
  p.q0 = Eigen::Quaterniond(T).normalized();
  const std::size_t i = cantilever_load(s, input, kind, "point_force");
  const YAML::Node cond = input["conditions"][i];
  const Eigen::Vector3d F = vec(cond["value"]) * curve_at(s, input, cond, qoi_time(s, input));
  const std::string qtype = qoi_type(s, input);
  if (qtype != "tip_position" && qtype != "tip_rotation_angle")
    bad(s, fmt::format("{} gives tip_position or tip_rotation_angle, not '{}'", kind, qtype));
  // 8000 RK4 steps: the tip changes by < 1e-9 of the length against 16000
  // (the reference test checks it).
  p.steps = 8000;
  // Studies evaluate the same reference for many runs: solve each problem once.
  static std::mutex mutex;
  static std::map<std::string, std::vector<double>> cache;
  std::string key = fmt::format("{} {:.17g} {}", qtype, p.length, p.steps);
  for (const Eigen::Vector3d& v : {p.CF, p.CM, p.K0, p.r0, F, Eigen::Vector3d(p.q0.coeffs().head<3>())})
    key += fmt::format(" {:.17g} {:.17g} {:.17g}", v.x(), v.y(), v.z());
  key += fmt::format(" {:.17g}", p.q0.w());
  const std::lock_guard lock(mutex);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  // Continuation in load increments of at most 1/20 of the load, more when
  // Newton fails to converge.
  std::optional<reference::RodState> end;
  for (int inc = 20; inc <= 320 && !end; inc *= 2) {
    try {
      end = reference::rod_tip_under_force(p, F, inc);
    } catch (const std::runtime_error&) {
    }
  }
  if (!end) bad(s, fmt::format("{}: the shooting did not converge for the tip force ({}, {}, {})", kind, F.x(), F.y(), F.z()));
  std::vector<double> out;
  if (qtype == "tip_position") out = {end->r.x(), end->r.y(), end->r.z()};
  else {
    // Rotation of the loaded tip triad against the unloaded one.
    const reference::RodState free_end = reference::rod_integrate(p, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    const Eigen::Quaterniond q(end->q[0], end->q[1], end->q[2], end->q[3]), q0(free_end.q[0], free_end.q[1], free_end.q[2], free_end.q[3]);
    out = {Eigen::AngleAxisd(q.normalized() * q0.normalized().conjugate()).angle()};
  }
  cache.emplace(key, out);
  return out;
}

}  // namespace

std::vector<double> analytic_reference(const StudyConfig& study, const YAML::Node& input) {
  try {
    switch (study.reference.type) {
      case Reference::Type::tube_plane_strain: return tube(study, input);
      case Reference::Type::beam_rollup: return rollup(study, input);
      case Reference::Type::beam_plastic_rollup: return plastic_rollup(study, input);
      case Reference::Type::beam_shooting: return shooting(study, input);
      case Reference::Type::value: return study.reference.value;
      default: return {};
    }
  } catch (const InputError& e) {
    // A key missing from the run's input (ConfigMap names the base file and
    // the key): say which study and reference asked for it.
    const std::string msg = e.what();
    if (msg.rfind(study.file.string(), 0) == 0) throw;
    throw InputError(fmt::format("{}: reference: {}", study.file.string(), msg));
  } catch (const YAML::Exception& e) {
    bad(study, fmt::format("cannot read the run's input: {}", e.what()));
  } catch (const std::invalid_argument& e) {
    bad(study, e.what());
  }
}

}  // namespace stentsim::study
