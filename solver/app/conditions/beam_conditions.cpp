// Conditions on beam bodies (nodes by beams::BeamNodeSelector):
//   clamp                positions, rotations and/or Hermite tangents held
//   point_force/_moment  dead nodal loads value·curve(t) (beams/beam_loads.hpp)
//   direction            "moves only along d" (two multipliers per node) or, for
//                        the stent file's axial fixation, "fixed along d" (one)
//   radial_displacement  (r − X)·e_r = value·curve(t) about an axis, a multiplier per node
//   fix_cylindrical      zero displacement components in the node's reference
//                        cylindrical frame (0 radial, 1 circumferential, 2 axial)
//   release              from `at` on, a radial_displacement condition becomes
//                        point forces equal to its last reactions × curve(t)
// A condition on a joint acts on its master node; on a slave node it is an error.
#include <fmt/format.h>

#include <algorithm>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/conditions/registry.hpp"
#include "solver/beams/beam_loads.hpp"
#include "solver/beams/direction_constraint.hpp"
#include "solver/beams/rigid_joints.hpp"

namespace stentsim::solver {
namespace {

/// Cylindrical frame (e_r, e_φ, axis) of a point about an axis.
Mat3 cylindrical_frame(const Vec3& x, const Vec3& origin, const Vec3& axis) {
  const Vec3 d = x - origin;
  Vec3 er = d - d.dot(axis) * axis;
  if (er.norm() < 1e-12) throw InputError("a node lies on the axis; its radial direction is undefined");
  er.normalize();
  Mat3 q;
  q.col(0) = er, q.col(1) = axis.cross(er), q.col(2) = axis;
  return q;
}

/// Words of a list ("position rotation", "radial, axial"), each one of `allowed`.
std::vector<std::string> words(ConfigMap& c, const std::string& key, const std::vector<std::string>& allowed) {
  const std::string text = c.string(key);
  std::vector<std::string> out;
  std::string w;
  for (std::size_t i = 0; i <= text.size(); ++i) {
    if (i == text.size() || text[i] == ' ' || text[i] == ',') {
      if (w.empty()) continue;
      if (std::find(allowed.begin(), allowed.end(), w) == allowed.end())
        c.fail(key, fmt::format("'{}' is not one of {}", w, fmt::join(allowed, ", ")));
      if (std::find(out.begin(), out.end(), w) == out.end()) out.push_back(w);
      w.clear();
    } else {
      w += text[i];
    }
  }
  if (out.empty()) c.fail(key, fmt::format("expected some of: {}", fmt::join(allowed, " ")));
  return out;
}

class BeamConditionSpec : public ConditionSpec {
 public:
  beams::BeamNodeSelector node;
  std::string curve;  // "" = constant 1

  /// The selected nodes (checked non-empty when read), masters only.
  std::vector<int> nodes(const SceneDesc& scene, const BuiltModel& m) const {
    const beams::BeamBodyDesc& desc = *m.beam_desc.at(body);
    const auto n = beams::select_beam_nodes(desc, node);
    log::info("condition '{}': {} node(s) of beam body '{}' ({})", name, n.size(), body, node.describe());
    if (!desc.joint_map.master.empty())
      for (int k : n) beams::require_master_node(desc.joint_map, k, fmt::format("{}: condition '{}'", scene.file.string(), name));
    return n;
  }
  beams::LoadScale scale(const SceneDesc& scene) const {
    const LoadCurve c = curve.empty() ? LoadCurve() : scene.curves.at(curve);
    return [c](double t) { return c(t); };
  }
};

template <class Spec>
std::shared_ptr<Spec> read_beam_condition(ConfigMap& c, SceneReader& r, const std::string& type) {
  auto s = std::make_shared<Spec>();
  const BodyDesc& b = r.body(c, "body", true, type);
  s->body = b.name;
  s->node = r.beam_nodes(c, "node", b);
  return s;
}

class ClampSpec : public BeamConditionSpec {
 public:
  bool position = true, rotation = true, tangent = false;
  void build(const SceneDesc& scene, BuiltModel& m, GlobalDof) const override {
    // Homogeneous: positions keep X, triads keep Λ₀ (rotation increments 0), tangents keep T₀.
    for (int n : nodes(scene, m)) {
      const beams::BeamNodeDofs& d = m.beam(body).dofs()[static_cast<std::size_t>(n)];
      auto fix3 = [&](const std::array<GlobalDof, 3>& dofs) {
        for (GlobalDof g : dofs)
          if (g >= 0) m.model.constraints.fix(g, [](double) { return 0.0; });
      };
      if (position) fix3(d.pos);
      if (rotation) fix3(d.rot);
      if (tangent) fix3(d.tan);
    }
  }
};

class NodalLoadSpec : public BeamConditionSpec {
 public:
  bool moment = false;
  Vec3 value = Vec3::Zero();  // N (force) or N mm (moment), dead (fixed in space)
  void build(const SceneDesc& scene, BuiltModel& m, GlobalDof) const override {
    for (int n : nodes(scene, m)) {
      const beams::BeamNodeDofs& d = m.beam(body).dofs()[static_cast<std::size_t>(n)];
      m.model.add_term<beams::NodalLoadTerm>(fmt::format("{}@{}", name, n), moment ? d.rot : d.pos, value, scale(scene));
    }
  }
};

class DirectionSpec : public BeamConditionSpec {
 public:
  bool from_file = false;  // the stent file's fixation directions
  Vec3 direction = Vec3::Zero();
  // The stent file's axial fixation is "fixed along d" (d·u = 0, one multiplier, free to expand
  // radially); the radial ones and a given direction are "moves only along d" (two multipliers).
  // Multipliers are laid out node after node in that order.
  bool fixed_along(const BuiltModel& m, std::size_t k) const { return from_file && m.beam_desc.at(body)->fixations.at(k).axial; }
  GlobalDof own_dofs(const BuiltModel& m) const override {
    const auto n = beams::select_beam_nodes(*m.beam_desc.at(body), node);
    GlobalDof count = 0;
    for (std::size_t k = 0; k < n.size(); ++k) count += fixed_along(m, k) ? 1 : 2;
    return count;
  }
  void build(const SceneDesc& scene, BuiltModel& m, GlobalDof first) const override {
    m.direction_multipliers.emplace_back(first, own_dofs(m));
    const auto n = nodes(scene, m);
    GlobalDof next = first;
    for (std::size_t k = 0; k < n.size(); ++k) {
      const beams::BeamNodeDofs& d = m.beam(body).dofs()[static_cast<std::size_t>(n[k])];
      const Vec3 dir = from_file ? m.beam_desc.at(body)->fixations[k].direction : direction;
      const std::string term = fmt::format("{}@{}", name, n[k]);
      if (fixed_along(m, k)) {
        m.model.add_term<beams::DirectionConstraintTerm>(term, d.pos, dir, next);
        next += 1;
      } else {
        m.model.add_term<beams::DirectionConstraintTerm>(term, d.pos, dir, std::array<GlobalDof, 2>{next, next + 1});
        next += 2;
      }
    }
  }
};

class RadialDisplacementSpec : public BeamConditionSpec {
 public:
  Vec3 origin = Vec3::Zero(), axis = Vec3::UnitZ();
  double value = 0.0;
  GlobalDof own_dofs(const BuiltModel& m) const override {
    return static_cast<GlobalDof>(beams::select_beam_nodes(*m.beam_desc.at(body), node).size());
  }
  void build(const SceneDesc& scene, BuiltModel& m, GlobalDof first) const override {
    const beams::BeamTerm& beam = m.beam(body);
    const auto& desc = *m.beam_desc.at(body);
    std::vector<beams::RadialDisplacementTerm::Node> rn;
    const auto n = nodes(scene, m);
    for (std::size_t k = 0; k < n.size(); ++k) {
      beams::RadialDisplacementTerm::Node x;
      x.pos = beam.dofs()[static_cast<std::size_t>(n[k])].pos;
      try {
        x.radial = cylindrical_frame(desc.body.nodes[static_cast<std::size_t>(n[k])].position, origin, axis).col(0);
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: condition '{}': node {}: {}", scene.file.string(), name, n[k], e.what()));
      }
      x.multiplier = first + static_cast<GlobalDof>(k);
      rn.push_back(x);
    }
    m.radial[name] = &m.model.add_term<beams::RadialDisplacementTerm>(name, std::move(rn), value, scale(scene));
  }
};

class FixCylindricalSpec : public BeamConditionSpec {
 public:
  Vec3 origin = Vec3::Zero(), axis = Vec3::UnitZ();
  std::vector<int> components;  // 0 radial, 1 circumferential, 2 axial
  void build(const SceneDesc& scene, BuiltModel& m, GlobalDof) const override {
    const auto& desc = *m.beam_desc.at(body);
    for (int n : nodes(scene, m)) {
      const beams::BeamNodeDofs& d = m.beam(body).dofs()[static_cast<std::size_t>(n)];
      if (d.pos[0] < 0 || d.pos[1] != d.pos[0] + 1 || d.pos[2] != d.pos[0] + 2)
        throw std::logic_error("beam position DOFs are not a consecutive triple");
      const Mat3 q = cylindrical_frame(desc.body.nodes[static_cast<std::size_t>(n)].position, origin, axis);
      if (const Mat3* old = m.model.constraints.frame(d.pos[0]); old && (*old - q).norm() > 1e-12)
        throw InputError(fmt::format("{}: condition '{}': node {} already has another nodal frame (another axis)",
                                     scene.file.string(), name, n));
      m.model.constraints.set_frame(d.pos[0], q);
      for (int comp : components) m.model.constraints.fix(d.pos[0] + comp, [](double) { return 0.0; });
    }
  }
};

class ReleaseSpec : public ConditionSpec {
 public:
  std::string from, curve;
  double at = 0.0;
  void add_stops(const SceneDesc& scene, std::vector<double>& stops) const override {
    // A release happens at the end of a converged step: its time is a stop inside the run.
    if (!(at > scene.stepping.t_start && at < scene.stepping.t_end))
      throw InputError(fmt::format("{}: condition '{}': release time at = {} must lie inside solver.time ({}, {})",
                                   scene.file.string(), name, at, scene.stepping.t_start, scene.stepping.t_end));
    stops.push_back(at);
  }
  void build(const SceneDesc& scene, BuiltModel& m, GlobalDof) const override {
    const double tol = 1e-9 * std::max(1.0, std::abs(scene.stepping.t_end));
    const LoadCurve c = scene.curves.at(curve);
    m.radial.at(from)->set_release(at, [c](double t) { return c(t); }, tol);
    log::info("condition '{}': '{}' becomes point forces equal to its reactions at t = {:g}, × curve '{}'", name, from, at, curve);
  }
};

Vec3 nonzero_direction(ConfigMap& c, const std::string& key) {
  Vec3 v = SceneReader::vec3(c, key);
  if (!(v.norm() > 0)) c.fail(key, "must be a non-zero vector");
  return v.normalized();
}

}  // namespace

ConditionKind clamp_condition() {
  return {"clamp", [](ConfigMap& c, SceneReader& r) {
            auto s = read_beam_condition<ClampSpec>(c, r, "clamp");
            // Hermite ends: position + rotation by default; the tangent carries the root shear strain.
            if (c.has("fix")) {
              const auto fix = words(c, "fix", {"position", "rotation", "tangent"});
              auto has = [&](const char* w) { return std::find(fix.begin(), fix.end(), w) != fix.end(); };
              s->position = has("position"), s->rotation = has("rotation"), s->tangent = has("tangent");
            }
            if (s->tangent && r.scene.body(s->body)->beam->body.interpolation != beams::BeamInterpolation::hermite3)
              c.fail("fix", "only Hermite (hermite3) beams have tangent DOFs");
            return s;
          }};
}

ConditionKind point_force_condition() {
  return {"point_force", [](ConfigMap& c, SceneReader& r) {
            auto s = read_beam_condition<NodalLoadSpec>(c, r, "point_force");
            s->value = SceneReader::vec3(c, "value");
            s->curve = r.curve(c, "curve", false);
            return s;
          }};
}

ConditionKind point_moment_condition() {
  return {"point_moment", [](ConfigMap& c, SceneReader& r) {
            auto s = read_beam_condition<NodalLoadSpec>(c, r, "point_moment");
            s->moment = true;
            s->value = SceneReader::vec3(c, "value");
            s->curve = r.curve(c, "curve", false);
            return s;
          }};
}

ConditionKind direction_condition() {
  return {"direction", [](ConfigMap& c, SceneReader& r) {
            auto s = read_beam_condition<DirectionSpec>(c, r, "direction");
            if (c.has("direction") && c.node()["direction"].IsScalar()) {
              s->from_file = c.choice("direction", {"file"}) == "file";
              if (s->node.kind != beams::BeamNodeSelector::Kind::fixations)
                c.fail("direction", "'file' takes the stent file's fixation directions; it needs node: fixations");
            } else {
              s->direction = nonzero_direction(c, "direction");
            }
            return s;
          }};
}

ConditionKind radial_displacement_condition() {
  return {"radial_displacement", [](ConfigMap& c, SceneReader& r) {
            auto s = read_beam_condition<RadialDisplacementSpec>(c, r, "radial_displacement");
            SceneReader::axis(c, "axis", s->origin, s->axis);
            s->value = c.quantity("value", units::kLength);
            s->curve = r.curve(c, "curve", false);
            return s;
          }};
}

ConditionKind fix_cylindrical_condition() {
  return {"fix_cylindrical", [](ConfigMap& c, SceneReader& r) {
            auto s = read_beam_condition<FixCylindricalSpec>(c, r, "fix_cylindrical");
            SceneReader::axis(c, "axis", s->origin, s->axis);
            for (const auto& w : words(c, "components", {"radial", "circumferential", "axial"}))
              s->components.push_back(w == "radial" ? 0 : w == "circumferential" ? 1 : 2);
            return s;
          }};
}

ConditionKind release_condition() {
  return {"release", [](ConfigMap& c, SceneReader& r) {
            auto s = std::make_shared<ReleaseSpec>();
            s->body = r.body(c, "body", true, "release").name;
            // The radial conditions become point forces equal to their last reactions, × curve(t) after `at`.
            s->from = c.string("from");
            const RadialDisplacementSpec* from = nullptr;
            for (const auto& other : r.scene.conditions)
              if (other->name == s->from) from = dynamic_cast<const RadialDisplacementSpec*>(other.get());
            if (!from) c.fail("from", fmt::format("no radial_displacement condition named '{}' before this one", s->from));
            if (from->body != s->body) c.fail("from", fmt::format("'{}' holds body '{}', not '{}'", s->from, from->body, s->body));
            for (const auto& other : r.scene.conditions)
              if (const auto* rel = dynamic_cast<const ReleaseSpec*>(other.get()); rel && rel->from == s->from)
                c.fail("from", fmt::format("'{}' is released twice", s->from));
            s->at = c.quantity("at", units::kTime);
            s->curve = r.curve(c, "curve", true);
            const double f = r.scene.curves.at(s->curve)(s->at);
            if (std::abs(f - 1.0) > 1e-12)
              c.fail("curve", fmt::format("the release curve '{}' must be 1 at the release time {} (it is {}): the forces start "
                                          "at the last reactions", s->curve, s->at, f));
            return s;
          }};
}

}  // namespace stentsim::solver
