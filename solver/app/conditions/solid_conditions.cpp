// Conditions on solid bodies:
//   pressure   follower pressure value·curve(t) on a surface selection (Nanson, DESIGN.md §5)
//   springs    omnidirectional Robin springs of stiffness per reference area
//   dirichlet  displacement components (global axes) value·curve(t) on a node
//              selection, or "radial only": the circumferential and axial
//              components about an axis held at zero in a nodal frame
#include <fmt/format.h>

#include <algorithm>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/app/body_surfaces.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/conditions/registry.hpp"
#include "solver/io/selection.hpp"
#include "solver/terms/robin_springs.hpp"

namespace stentsim::solver {
namespace {

/// The selected boundary faces of the body (of its solid cells), never empty.
std::vector<fem::Face> selected_faces(const SceneDesc& scene, const std::string& condition, const SolidBody& body,
                                      const Selector& where) {
  auto faces = selected_boundary_faces(scene, fmt::format("condition '{}'", condition), body, where);
  log::info("condition '{}': {} faces of body '{}'", condition, faces.size(), body.name());
  return faces;
}

class PressureSpec : public ConditionSpec {
 public:
  Selector where;
  double value = 0.0;
  std::string curve;
  void build(const SceneDesc& scene, BuiltModel& m, GlobalDof) const override {
    SolidBody& body = m.solid(this->body);
    const LoadCurve c = curve.empty() ? LoadCurve() : scene.curves.at(curve);
    m.pressures.emplace_back(name, &m.model.add_term<FollowerPressure>(name, body, selected_faces(scene, name, body, where), value, c));
  }
};

class SpringsSpec : public ConditionSpec {
 public:
  Selector where;
  double stiffness = 0.0;
  void build(const SceneDesc& scene, BuiltModel& m, GlobalDof) const override {
    SolidBody& body = m.solid(this->body);
    m.model.add_term<RobinSprings>(name, body, selected_faces(scene, name, body, where), stiffness);
  }
};

class DirichletSpec : public ConditionSpec {
 public:
  Selector where;
  double value = 0.0;
  std::string curve;
  std::vector<int> components;  // global axes
  bool radial_only = false;
  Vec3 origin = Vec3::Zero(), axis = Vec3::UnitZ();

  void build(const SceneDesc& scene, BuiltModel& m, GlobalDof) const override {
    const std::string file = scene.file.string();
    SolidBody& body = m.solid(this->body);
    const LoadCurve c = curve.empty() ? LoadCurve() : scene.curves.at(curve);
    const auto nodes = select_nodes(body.mesh(), where);
    if (nodes.empty())
      throw InputError(fmt::format("{}: condition '{}': the node selection ({}) selects no node of body '{}'", file, name,
                                   where.describe(), this->body));
    log::info("condition '{}': {} nodes of body '{}'", name, nodes.size(), this->body);
    for (auto n : nodes) {
      const GlobalDof d0 = body.dof(n, 0);
      if (radial_only) {
        if (m.fixed_nodes.count(d0))
          throw InputError(fmt::format("{}: condition '{}' (radial only) and '{}' (global components) both hold node {} of body '{}'",
                                       file, name, m.fixed_nodes[d0], n, this->body));
        const Vec3 d = body.mesh().points[n] - origin;
        Vec3 er = d - d.dot(axis) * axis;
        if (er.norm() < 1e-12)
          throw InputError(fmt::format("{}: condition '{}': node {} lies on the axis; its radial direction is undefined", file, name, n));
        er.normalize();
        Mat3 q;
        q.col(0) = er, q.col(1) = axis.cross(er), q.col(2) = axis;
        m.model.constraints.set_frame(d0, q);
        m.model.constraints.fix(d0 + 1, [](double) { return 0.0; });
        m.model.constraints.fix(d0 + 2, [](double) { return 0.0; });
        m.framed_nodes[d0] = name;
      } else {
        if (m.framed_nodes.count(d0))
          throw InputError(fmt::format("{}: condition '{}' (global components) and '{}' (radial only) both hold node {} of body '{}'",
                                       file, name, m.framed_nodes[d0], n, this->body));
        for (int comp : components) m.model.constraints.fix(d0 + comp, [v = value, c](double t) { return v * c(t); });
        m.fixed_nodes[d0] = name;
      }
    }
  }
};

}  // namespace

ConditionKind pressure_condition() {
  return {"pressure", [](ConfigMap& c, SceneReader& r) {
            auto s = std::make_shared<PressureSpec>();
            s->body = r.body(c, "body", false, "pressure").name;
            s->where = read_selector(c, "surface");
            s->value = c.quantity("value", units::kPressure);
            s->curve = r.curve(c, "curve", false);
            return s;
          }};
}

ConditionKind springs_condition() {
  return {"springs", [](ConfigMap& c, SceneReader& r) {
            auto s = std::make_shared<SpringsSpec>();
            s->body = r.body(c, "body", false, "springs").name;
            s->where = read_selector(c, "surface");
            s->stiffness = c.quantity("stiffness", units::kStiffnessPerArea, std::nullopt, Range::positive());
            return s;
          }};
}

ConditionKind dirichlet_condition() {
  return {"dirichlet", [](ConfigMap& c, SceneReader& r) {
            auto s = std::make_shared<DirichletSpec>();
            s->body = r.body(c, "body", false, "dirichlet").name;
            s->where = read_selector(c, "nodes");
            s->value = c.quantity("value", units::kLength, 0.0);
            s->curve = r.curve(c, "curve", false);
            if (auto ro = c.optional_map("radial_only")) {
              s->radial_only = true;
              s->origin = SceneReader::vec3(*ro, "origin", Vec3::Zero());
              s->axis = SceneReader::vec3(*ro, "axis", Vec3::UnitZ()).normalized();
              ro->finish();
              if (s->value != 0.0) c.fail("value", "radial_only fixes the non-radial components to zero; value must be 0");
            } else {
              // "x", "xy", "x z", "xyz": the fixed global components.
              const std::string comps = c.string("components");
              for (char ch : comps) {
                if (ch == ' ' || ch == ',') continue;
                if (ch < 'x' || ch > 'z') c.fail("components", fmt::format("'{}' is not a list of x, y, z (e.g. 'xz')", comps));
                if (std::find(s->components.begin(), s->components.end(), ch - 'x') == s->components.end())
                  s->components.push_back(ch - 'x');
              }
              if (s->components.empty()) c.fail("components", "expected at least one of x, y, z (e.g. 'xyz')");
            }
            return s;
          }};
}

}  // namespace stentsim::solver
