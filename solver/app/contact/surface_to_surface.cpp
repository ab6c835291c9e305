// Scene kind `surface_to_surface` (solver/contact/surface_to_surface_pair.hpp):
//   - name: balloon_artery
//     type: surface_to_surface
//     slave: {body: balloon, surface: {cell_array: {name: FaceGroup, value: 6}}}   # the finer mesh (DESIGN.md §8)
//     master: {body: artery, surface: {cell_array: {name: FaceGroup, value: 1}}}
//     penalty: 5 N/mm^3                 # ε (paper 2.5, read per DESIGN.md §8)
//     gauss_points: 4                   # per direction and slave face
//     smoothing: 0 mm                   # g0 of the C¹ law
//     search_margin: 0.1 mm             # default: the slave's largest face size
//     max_flips: 8
//     times: {max: 1, after: 2}         # optional: summary entries at these times
// Outputs: history.csv contact_<name>_force (Σ_j p_j A_j, the normal contact force summed
// as magnitudes over the slave nodes, N, as the beam pairs' Σ w |f|) and
// contact_<name>_active_nodes; point arrays on the slave body's frames
// ContactPressure_<name> (MPa per current area), ContactGap_<name> (the
// nodal mean gap g̃_j/A_j, mm) and ContactSlave_<name> (1 on the slave surface,
// where the other two are defined; 0 elsewhere); summary.yaml contact_pressure_max_<name>,
// contact_force_<name>, contact_active_nodes_<name> at the end and, suffixed
// _<label>, at each of `times`. A slave surface that starts inside the master
// is an input error naming the place (DESIGN.md §8).
#include <fmt/format.h>

#include <cmath>
#include <map>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/app/body_surfaces.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/contact/registry.hpp"
#include "solver/app/contact/surface_self_intersection.hpp"
#include "solver/app/run_observer.hpp"
#include "solver/contact/surface_to_surface_pair.hpp"
#include "solver/io/selection.hpp"

namespace stentsim::solver {
namespace {

// Bodies that touch in the initial state (gap 0 up to round-off) are not penetrating.
constexpr double kTouchTolerance = 1e-9;  // mm

using contact::SurfaceToSurfacePair;

struct SurfaceMeasure {
  double force = 0.0, pressure_max = 0.0;
  int active = 0;
  void put(HistoryArchive& out, const std::string& prefix) const {
    out.put(prefix + "force", force), out.put(prefix + "pressure_max", pressure_max);
    out.put(prefix + "active_nodes", static_cast<double>(active));
  }
  static SurfaceMeasure get(const HistoryArchive& in, const std::string& prefix) {
    return {in.get_scalar(prefix + "force"), in.get_scalar(prefix + "pressure_max"), static_cast<int>(in.get_scalar(prefix + "active_nodes"))};
  }
};

class SurfaceToSurfaceOutput : public RunObserver {
 public:
  SurfaceToSurfaceOutput(const SurfaceToSurfacePair& pair, std::string slave_body, std::map<std::string, double> times, double t_end)
      : pair_(pair), slave_body_(std::move(slave_body)), times_(std::move(times)), t_end_(t_end) {}
  void start(const Eigen::VectorXd& u, bool) override { now_ = measure(u); }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    now_ = measure(u);
    for (const auto& [label, t] : times_)
      if (same_time(r.time, t, t_end_)) at_[label] = now_;
  }
  std::vector<std::string> history_columns() const override {
    return {fmt::format("contact_{}_force", pair_.name()), fmt::format("contact_{}_active_nodes", pair_.name())};
  }
  std::vector<double> history_values() const override { return {now_.force, static_cast<double>(now_.active)}; }
  void decorate(std::vector<std::pair<std::string, MeshData>>& meshes, const Eigen::VectorXd& u) const override {
    const auto state = pair_.evaluate(u);
    for (auto& [name, mesh] : meshes) {
      if (name != slave_body_) continue;
      // Nodes off the slave surface: 0 (no NaN in outputs; ContactSlave tells them apart).
      DataArray pressure{1, std::vector<double>(mesh.points.size(), 0.0)}, gap{1, std::vector<double>(mesh.points.size(), 0.0)},
          slave{1, std::vector<double>(mesh.points.size(), 0.0)};
      for (const auto& n : state.nodes) {
        if (n.body_node >= mesh.points.size()) continue;
        pressure.values[n.body_node] = n.current_pressure;
        gap.values[n.body_node] = n.mean_gap;
        slave.values[n.body_node] = 1.0;
      }
      mesh.point_data["ContactSlave_" + pair_.name()] = slave;
      mesh.point_data["ContactPressure_" + pair_.name()] = pressure;
      mesh.point_data["ContactGap_" + pair_.name()] = gap;
    }
  }
  std::string checkpoint_name() const override { return "contact/" + pair_.name(); }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    for (const auto& [label, m] : at_) m.put(out, prefix + "at/" + label + "/");
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    for (const auto& [label, t] : times_)
      if (in.has(prefix + "at/" + label + "/force")) at_[label] = SurfaceMeasure::get(in, prefix + "at/" + label + "/");
  }
  void summarize(Summary& s, const RunEnd&) const override {
    auto put = [&](const SurfaceMeasure& m, const std::string& suffix) {
      s.set("contact_pressure_max_" + pair_.name() + suffix, m.pressure_max, "MPa");
      s.set("contact_force_" + pair_.name() + suffix, m.force, "N");
      s.set("contact_active_nodes_" + pair_.name() + suffix, static_cast<double>(m.active));
    };
    put(now_, "");
    for (const auto& [label, m] : at_) put(m, "_" + label);
  }

 private:
  SurfaceMeasure measure(const Eigen::VectorXd& u) const {
    const auto state = pair_.evaluate(u);
    SurfaceMeasure m;
    for (const auto& n : state.nodes) {
      if (!n.active) continue;
      m.force += n.pressure * n.area;  // the normal force on the node
      ++m.active;
      m.pressure_max = std::max(m.pressure_max, n.current_pressure);
    }
    return m;
  }
  const SurfaceToSurfacePair& pair_;
  std::string slave_body_;
  std::map<std::string, double> times_;
  double t_end_;
  SurfaceMeasure now_;
  std::map<std::string, SurfaceMeasure> at_;
};

struct SideDesc {
  std::string body;
  Selector surface;
};

class SurfaceToSurfaceSpec : public ContactSpec {
 public:
  SideDesc slave, master;
  contact::SurfaceToSurfaceSettings settings;
  std::map<std::string, double> times;

  std::unique_ptr<contact::ContactSurface> surface(const SceneDesc& scene, BuiltModel& m, const SideDesc& side,
                                                   const char* role) const {
    SolidBody& body = m.solid(side.body);
    const auto faces = selected_boundary_faces(scene, fmt::format("contact '{}' ({})", name, role), body, side.surface);
    return std::make_unique<contact::ContactSurface>(name + ":" + side.body, body, faces);
  }

  void build(const SceneDesc& scene, BuiltModel& m) const override {
    auto s = surface(scene, m, slave, "slave");
    auto ms = surface(scene, m, master, "master");
    contact::SurfaceToSurfaceSettings set = settings;
    if (!(set.search_margin > 0)) {
      // About one slave face: far enough to catch the approach within a step.
      double h = 0.0;
      for (const auto& f : s->faces())
        for (int k = 1; k < f.count; ++k) h = std::max(h, (s->x(f.node[k]) - s->x(f.node[0])).norm());
      set.search_margin = h;
    }
    const std::string slave_name = s->name(), master_name = ms->name();
    auto& pair = m.model.add_term<SurfaceToSurfacePair>(name, std::move(s), std::move(ms), set);
    const auto state = pair.evaluate(Eigen::VectorXd::Zero(m.model.dofs.size()));
    double min_gap = std::numeric_limits<double>::infinity();
    for (const auto& p : state.points) {
      if (p.master_face < 0) continue;
      min_gap = std::min(min_gap, p.gap);
      if (p.gap < -kTouchTolerance)
        throw InputError(fmt::format("{}: contact '{}': the slave surface of '{}' starts inside the master surface of '{}': Gauss point {} "
                                     "of slave face {} at ({:.4f}, {:.4f}, {:.4f}) mm has gap {:.4g} mm; move the bodies apart",
                                     scene.file.string(), name, slave.body, master.body, p.gauss_point, p.slave_face,
                                     p.position.x(), p.position.y(), p.position.z(), p.gap));
    }
    log::info("contact '{}': surface-to-surface, slave {} ({} faces) on master {} ({} faces), penalty {:g} N/mm^3, {}x{} Gauss "
              "points per slave face, search margin {:g} mm; smallest initial gap {:.4g} mm",
              name, slave_name, pair.slave().faces().size(), master_name, pair.master().faces().size(), set.law.epsilon,
              set.gauss_points, set.gauss_points, set.search_margin, min_gap);
    m.notes.push_back(fmt::format("contact {}: surface-to-surface node-wise penalty (mortar-type weighted gaps, element-based "
                                  "integration {}x{}), slave {} master {}, epsilon {:g} N/mm^3, frictionless",
                                  name, set.gauss_points, set.gauss_points, slave.body, master.body, set.law.epsilon));
    m.observers.push_back(std::make_unique<SurfaceToSurfaceOutput>(pair, slave.body, times, scene.stepping.t_end));
    // Self-contact is not modelled: a surface folded through itself is detected and warned about.
    if (m.self_intersection_checked_solids.insert(slave.body).second)
      m.observers.push_back(make_surface_self_intersection_check(pair.slave(), slave.body));
    if (m.self_intersection_checked_solids.insert(master.body).second)
      m.observers.push_back(make_surface_self_intersection_check(pair.master(), master.body));
  }
};

SideDesc read_side(ConfigMap& c, const std::string& key, SceneReader& r) {
  ConfigMap m = c.map(key);
  SideDesc s;
  s.body = r.body(m, "body", false, "surface_to_surface").name;
  s.surface = read_selector(m, "surface");
  m.finish();
  return s;
}

}  // namespace

ContactKind surface_to_surface_contact() {
  return {"surface_to_surface", [](ConfigMap& c, SceneReader& r) {
            auto s = std::make_shared<SurfaceToSurfaceSpec>();
            s->slave = read_side(c, "slave", r);
            s->master = read_side(c, "master", r);
            if (s->slave.body == s->master.body) c.fail("master", "slave and master must be different bodies (no self-contact)");
            s->settings.law.epsilon = c.quantity("penalty", units::kStiffnessPerArea, std::nullopt, Range::positive());
            s->settings.law.smoothing = c.quantity("smoothing", units::kLength, 0.0, Range::non_negative());
            s->settings.gauss_points = c.integer("gauss_points", 4, Range::between(1, 32));
            s->settings.search_margin = c.quantity("search_margin", units::kLength, 0.0, Range::non_negative());
            s->settings.max_flips = c.integer("max_flips", 8, Range::between(1, 1000));
            s->times = read_report_times(c, "times", r);
            return s;
          }};
}

}  // namespace stentsim::solver
