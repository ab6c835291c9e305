#include "solver/beams/beam_scene.hpp"

#include "common/error.hpp"
#include "common/mesh_data.hpp"
#include "common/units.hpp"
#include "solver/beams/rotation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

namespace stentsim::solver::beams {
namespace {

Eigen::Vector3d vec3(ConfigMap& m, const std::string& key) {
  const auto v = m.numbers(key, 3);
  return {v[0], v[1], v[2]};
}

using Curve = std::function<void(double s, Eigen::Vector3d& r, Eigen::Matrix3d& triad)>;

// Equal elements along a curve given by arc length; numbering as in the header.
BeamBodyDefinition discretize(const Curve& curve, double length, int n, BeamInterpolation kind) {
  BeamBodyDefinition b;
  b.interpolation = kind;
  auto node = [&](double s) {
    BeamNode nd;
    Eigen::Matrix3d T;
    curve(s, nd.position, T);
    nd.triad = Eigen::Quaterniond(T).normalized();
    return nd;
  };
  for (int i = 0; i <= n; ++i) b.nodes.push_back(node(length * i / n));
  for (int e = 0; e < n; ++e) {
    BeamElement el{e, e + 1, -1};
    if (kind == BeamInterpolation::hermite3) {
      el.mid = static_cast<int>(b.nodes.size());
      b.nodes.push_back(node(length * (e + 0.5) / n));
    }
    b.elements.push_back(el);
  }
  return b;
}

BeamSection read_section(ConfigMap& beam, double E, double G) {
  ConfigMap s = beam.map("section");
  BeamSection sec;
  if (s.has("radius")) {
    const double R = s.quantity("radius", units::kLength, std::nullopt, Range::positive());
    const double k = s.number("shear_factor", 6.0 / 7.0, Range{0.0, 1.0, false, true});
    sec = BeamSection::circular(E, G, R, k);
  } else {
    const double A = s.number("A", std::nullopt, Range::positive());
    sec = BeamSection::from_values(E, G, A, s.number("A2", A, Range::positive()), s.number("A3", A, Range::positive()),
                                   s.number("I2", std::nullopt, Range::positive()),
                                   s.number("I3", std::nullopt, Range::positive()),
                                   s.number("IT", std::nullopt, Range::positive()));
  }
  s.finish();
  return sec;
}

}  // namespace

namespace {

// The material of a beam body: E, G and optionally the plastic bending law
// (`material: stent` or `plastic: {E_ep, M_y0}`; the radius is set later).
struct BeamMaterial {
  double E = 0, G = 0;
  std::optional<PlasticBendingLaw> plastic;
};

BeamMaterial read_beam_material(ConfigMap& beam) {
  BeamMaterial m;
  if (beam.has("material")) {
    beam.choice("material", {"stent"});
    if (beam.has("E") || beam.has("G") || beam.has("plastic"))
      beam.fail("material", "the stent preset sets E, G and the plastic law; remove E, G and plastic");
    m.plastic = PlasticBendingLaw::stent_preset();
    m.E = m.plastic->E, m.G = m.plastic->G;
    return m;
  }
  m.E = beam.quantity("E", units::kPressure, std::nullopt, Range::positive());
  m.G = beam.quantity("G", units::kPressure, std::nullopt, Range::positive());
  if (auto p = beam.optional_map("plastic")) {
    PlasticBendingLaw law;
    law.E = m.E, law.G = m.G;
    law.E_ep = p->quantity("E_ep", units::kPressure, std::nullopt, Range::positive());
    law.M_y0 = p->number("M_y0", std::nullopt, Range::positive());  // N mm
    if (law.E_ep >= m.E) p->fail("E_ep", "the elasto-plastic modulus must be below E");
    p->finish();
    m.plastic = law;
  }
  return m;
}

// Elasto-plastic bending needs a circular section (App. C; DESIGN.md §8).
void make_plastic(BeamBodyDesc& d, const BeamMaterial& m, ConfigMap& beam) {
  if (!m.plastic) return;
  BeamSection& sec = d.body.section;
  if (!(sec.radius > 0.0))
    beam.fail(beam.has("material") ? "material" : "plastic", "elasto-plastic bending needs a circular section ({radius: R})");
  PlasticBendingLaw law = *m.plastic;
  law.radius = sec.radius;
  law.validate((beam.file().string() + ": " + beam.dotted_path()).c_str());
  sec = BeamSection::circular_plastic(law);
}

}  // namespace

std::vector<BeamNodeDofs> BeamBodyDesc::number_dofs(GlobalDof first, GlobalDof* next) const {
  if (joint_map.master.empty()) return number_beam_dofs(body, first, next);
  return number_joined_beam_dofs(body, joint_map, first, next);
}

BeamBodyDesc read_beam_body(ConfigMap& beam) {
  BeamBodyDesc d;
  const bool has_file = beam.has("file"), has_gen = beam.has("generate");
  if (has_file == has_gen) beam.fail("", "give exactly one of 'file' (the stent stage's stent.vtu) or 'generate'");
  const BeamMaterial mat = read_beam_material(beam);
  const double E = mat.E, G = mat.G;
  const std::string where = beam.file().string() + ": " + beam.dotted_path();
  if (has_file) {
    const auto path = beam.path("file");
    if (path.extension() != ".vtu") beam.fail("file", "expected a .vtu file (the stent stage's stent.vtu)");
    if (!std::filesystem::is_regular_file(path)) beam.fail("file", fmt::format("no such file: {}", path.string()));
    if (beam.has("section")) beam.fail("section", "a stent file carries its section (SectionRadius); remove 'section'");
    if (beam.has("interpolation") && beam.string("interpolation") != "hermite3")
      beam.fail("interpolation", "stent files hold Hermite elements (end, end, middle node): use hermite3");
    StentBeams s;
    try {
      s = stent_beams_from_mesh(read_vtu(path.string()), E, G, path.string());
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      beam.fail("file", fmt::format("cannot read {}: {}", path.string(), e.what()));
    }
    d.body = std::move(s.body);
    d.joints = std::move(s.joints);
    d.fixations = std::move(s.fixations);
    d.element_ring = std::move(s.element_ring);
    d.source = path.string();
    d.body.gauss_points = beam.integer("gauss_points", 0, Range::between(0, 10));
    make_plastic(d, mat, beam);
    d.couple_joints = beam.choice("joints", {"rigid", "none"}, "rigid") == "rigid";
    if (d.couple_joints && !d.joints.empty()) {
      try {
        d.joint_map = make_joint_map(d.body, d.joints, path.string());
      } catch (const InputError& e) {
        beam.fail("file", e.what());
      }
    }
    return d;
  }
  if (beam.has("joints")) beam.fail("joints", "generated bodies have no joints (joints come from a stent file)");
  const std::string interp = beam.choice("interpolation", {"hermite3", "lagrange2"}, "hermite3");
  const BeamInterpolation kind = interp == "hermite3" ? BeamInterpolation::hermite3 : BeamInterpolation::lagrange2;
  ConfigMap g = beam.map("generate");
  const std::string type = g.choice("type", {"line", "arc"});
  const int n = g.integer("elements", std::nullopt, Range::between(1, 1000000));
  if (type == "line") {
    const Eigen::Vector3d a = vec3(g, "start"), b = vec3(g, "end");
    const double L = (b - a).norm();
    if (!(L > 0.0)) g.fail("end", "must differ from start");
    const Eigen::Vector3d d1 = (b - a) / L;
    Eigen::Vector3d hint;
    if (g.has("d2")) {
      hint = vec3(g, "d2");
    } else {  // the global axis least aligned with the beam
      Eigen::Index k;
      d1.cwiseAbs().minCoeff(&k);
      hint = Eigen::Vector3d::Unit(k);
    }
    Eigen::Vector3d d2 = hint - hint.dot(d1) * d1;
    if (d2.norm() < 1e-8 * std::max(1.0, hint.norm())) g.fail("d2", "must not be parallel to the beam");
    d2.normalize();
    Eigen::Matrix3d T;
    T << d1, d2, d1.cross(d2);
    d.body = discretize([=](double s, Eigen::Vector3d& r, Eigen::Matrix3d& F) { r = a + s * d1, F = T; }, L, n, kind);
    d.source = fmt::format("generated line, {} {} elements, length {:g}", n, interp, L);
  } else {
    const Eigen::Vector3d c = vec3(g, "center"), a = vec3(g, "start");
    Eigen::Vector3d nrm = vec3(g, "normal");
    const double angle = g.number("angle_deg", std::nullopt, Range{0.0, 360.0, false, true}) * std::numbers::pi / 180.0;
    const double R = (a - c).norm();
    if (!(R > 0.0)) g.fail("start", "must differ from center");
    if (!(nrm.norm() > 0.0)) g.fail("normal", "must be a non-zero vector");
    nrm.normalize();
    const Eigen::Vector3d e_r = (a - c) / R;
    if (std::abs(e_r.dot(nrm)) > 1e-8) g.fail("normal", "must be perpendicular to start − center");
    const Eigen::Vector3d e_t = nrm.cross(e_r);
    auto curve = [=](double s, Eigen::Vector3d& r, Eigen::Matrix3d& F) {
      const double p = s / R;
      const Eigen::Vector3d radial = std::cos(p) * e_r + std::sin(p) * e_t;
      r = c + R * radial;
      const Eigen::Vector3d d1 = nrm.cross(radial);
      F << d1, radial, d1.cross(radial);
    };
    d.body = discretize(curve, R * angle, n, kind);
    d.source = fmt::format("generated arc, {} {} elements, radius {:g}, angle {:g} rad", n, interp, R, angle);
  }
  g.finish();
  d.body.section = read_section(beam, E, G);
  d.body.section.validate(where);
  d.body.gauss_points = beam.integer("gauss_points", 0, Range::between(0, 10));
  make_plastic(d, mat, beam);
  return d;
}

std::string BeamNodeSelector::describe() const {
  switch (kind) {
    case Kind::first: return "first";
    case Kind::last: return "last";
    case Kind::fixations: return "fixations";
    case Kind::joints: return "joints";
    case Kind::index: {
      std::string t = "index [";
      for (std::size_t i = 0; i < indices.size(); ++i) t += (i ? ", " : "") + std::to_string(indices[i]);
      return t + "]";
    }
    case Kind::point: return fmt::format("point ({:g}, {:g}, {:g})", point.x(), point.y(), point.z());
  }
  return "?";
}

BeamNodeSelector read_beam_node_selector(ConfigMap& cfg, const std::string& key) {
  BeamNodeSelector s;
  if (!cfg.has(key)) cfg.fail(key, "expected a beam node: first, last, fixations, joints, {point: [x, y, z]} or {index: [n]}");
  if (cfg.node()[key].IsScalar()) {
    const std::string w = cfg.choice(key, {"first", "last", "fixations", "joints"});
    s.kind = w == "first" ? BeamNodeSelector::Kind::first
             : w == "last" ? BeamNodeSelector::Kind::last
             : w == "joints" ? BeamNodeSelector::Kind::joints
                           : BeamNodeSelector::Kind::fixations;
    return s;
  }
  ConfigMap m = cfg.map(key);
  if (m.has("index")) {
    s.kind = BeamNodeSelector::Kind::index;
    const YAML::Node n = m.node()["index"];
    const auto v = m.numbers("index", n.IsSequence() ? n.size() : 1);
    for (double x : v) {
      if (x < 0 || x != std::floor(x)) m.fail("index", "expected non-negative node numbers");
      s.indices.push_back(static_cast<int>(x));
    }
    if (s.indices.empty()) m.fail("index", "expected at least one node number");
    m.finish();
    return s;
  }
  s.kind = BeamNodeSelector::Kind::point;
  s.point = vec3(m, "point");
  s.tolerance = m.quantity("tolerance", units::kLength, -1.0);
  m.finish();
  return s;
}

std::vector<int> select_beam_nodes(const BeamBodyDesc& d, const BeamNodeSelector& s) {
  const BeamBodyDefinition& b = d.body;
  const std::vector<bool> ends = beam_end_nodes(b);
  std::vector<int> out;
  switch (s.kind) {
    case BeamNodeSelector::Kind::first:
      for (int i = 0; i < static_cast<int>(ends.size()); ++i)
        if (ends[static_cast<std::size_t>(i)]) return {i};
      return {};
    case BeamNodeSelector::Kind::last: {
      // generated bodies: node N (end nodes come first); files: the last end node
      for (int i = static_cast<int>(ends.size()) - 1; i >= 0; --i)
        if (ends[static_cast<std::size_t>(i)]) return {i};
      return {};
    }
    case BeamNodeSelector::Kind::fixations:
      for (const auto& f : d.fixations) out.push_back(f.node);
      return out;
    case BeamNodeSelector::Kind::joints: {
      if (d.joint_map.master.empty()) return out;
      std::vector<bool> seen(b.nodes.size(), false);
      for (const auto& j : d.joints) {
        const int m = d.joint_map.master[static_cast<std::size_t>(j[0])];
        if (!seen[static_cast<std::size_t>(m)]) seen[static_cast<std::size_t>(m)] = true, out.push_back(m);
      }
      std::sort(out.begin(), out.end());
      return out;
    }
    case BeamNodeSelector::Kind::index:
      for (int i : s.indices) {
        if (i >= static_cast<int>(b.nodes.size()) || !ends[static_cast<std::size_t>(i)])
          throw InputError(fmt::format("beam node index {} is not an element end node (0..{})", i, b.nodes.size() - 1));
        out.push_back(i);
      }
      return out;
    case BeamNodeSelector::Kind::point: {
      Eigen::Vector3d lo = b.nodes[0].position, hi = lo;
      for (const auto& n : b.nodes) lo = lo.cwiseMin(n.position), hi = hi.cwiseMax(n.position);
      const double tol = s.tolerance >= 0 ? s.tolerance : 1e-6 * std::max((hi - lo).norm(), 1e-300);
      for (int i = 0; i < static_cast<int>(b.nodes.size()); ++i)
        if (ends[static_cast<std::size_t>(i)] && (b.nodes[static_cast<std::size_t>(i)].position - s.point).norm() <= tol) {
          // a joint acts through its master node
          const int m = d.joint_map.master.empty() ? i : d.joint_map.master[static_cast<std::size_t>(i)];
          if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
        }
      return out;
    }
  }
  return out;
}

Eigen::Vector3d unwrap_rotation_vector(const Eigen::Quaterniond& relative, const Eigen::Vector3d& previous) {
  const Eigen::Vector3d psi = quat_log(relative);
  const double theta = psi.norm();
  // Direction of the branch: the axis of psi, or of `previous` at zero rotation.
  Eigen::Vector3d axis = theta > 1e-300 ? Eigen::Vector3d(psi / theta)
                                        : (previous.norm() > 0 ? Eigen::Vector3d(previous.normalized()) : Eigen::Vector3d::UnitZ());
  Eigen::Vector3d best = psi;
  double best_d = (psi - previous).norm();
  for (int k = -4; k <= 4; ++k) {
    const Eigen::Vector3d v = axis * (theta + 2.0 * std::numbers::pi * k);
    if ((v - previous).norm() < best_d) best = v, best_d = (v - previous).norm();
  }
  return best;
}

}  // namespace stentsim::solver::beams
