// stent_expansion (a stent file's beam body; the case's solve stage adds it):
// ring by ring (ring_geometry.hpp) the mean diameter about the ring's own
// deformed centroid, normal to the local axis of the ring-centroid curve; the
// stent's diameter is the mean over the rings. At each labelled time
// (`times: {max: 1, after: 2}`): stent_diameter_<label>, the ring diameters,
// the centroid curve's largest curvature and the largest bending moment;
// recoil_percent = 100 (D_max − D_after)/D_max. Dogboning (DESIGN.md §8) is
// judged by its maximum over the inflation (t ≤ the `max` time) and the
// pressure of the named pressure condition where it occurs; its value at
// 0.8·p_max (linear in pressure between the two steps around it) and the
// /r_central variant are reported too (three rings or more). The ring nodes
// are the end nodes of the ring's strut elements (crowns and the nodes
// between a strut's elements), on the strut centerlines. Summary keys carry no prefix (one
// stent_expansion per scene; not with ring_expansion, whose recoil_percent it shares).
#include <fmt/format.h>

#include <Eigen/Geometry>

#include <set>

#include "common/error.hpp"
#include "solver/app/body_surfaces.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/qoi/beam_measures.hpp"
#include "solver/app/qoi/registry.hpp"
#include "solver/app/qoi/ring_geometry.hpp"
#include "solver/app/run_observer.hpp"

namespace stentsim::solver {
namespace {

class StentSpec : public QoiSpec {
 public:
  std::string pressure;                  // a pressure condition's name ("" : no pressures)
  std::map<std::string, double> times;   // label -> time
  std::string where;                     // the scene file and entry, for errors found while building
  bool unprefixed() const override { return true; }
  std::unique_ptr<RunObserver> observer(const SceneDesc& scene, const BuiltModel& m) const override;
};

class StentExpansion : public RunObserver {
 public:
  StentExpansion(const StentSpec& spec, const BuiltModel& m, double t_end)
      : spec_(spec), beam_(m.beam(spec.body)), t_end_(t_end) {
    const beams::BeamBodyDesc& desc = *m.beam_desc.at(spec.body);
    if (desc.element_ring.size() != desc.body.elements.size())
      throw InputError(fmt::format("{}: qoi '{}': body '{}' ({}) has no ring membership (the stent stage's MemberKind and "
                                   "Ring cell arrays); stent_expansion needs a stent file",
                                   spec.where, spec.name, spec.body, desc.source));
    ring_nodes_ = stent_ring_nodes(desc);
    if (ring_nodes_.empty()) throw InputError(fmt::format("{}: qoi '{}': body '{}' has no strut elements", spec.where, spec.name, spec.body));
    if (!spec.pressure.empty()) {
      for (const auto& [name, p] : m.pressures)
        if (name == spec.pressure) pressure_ = p;
      if (!pressure_)
        throw InputError(fmt::format("{}: qoi '{}': 'pressure: {}' names no pressure condition", spec.where, spec.name,
                                     spec.pressure));
    }
    const auto mx = spec.times.find("max");
    t_inflated_ = mx == spec.times.end() ? t_end : mx->second;
  }

  void start(const Eigen::VectorXd& u, bool restarted) override {
    now_ = measure(u);
    if (!restarted) at_["initial"] = now_;
  }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    now_ = measure(u);
    const double p = pressure_ ? pressure_->pressure(r.time) : 0.0;
    if (r.time <= t_inflated_ * (1 + 1e-12)) series_.push_back({r.time, p, now_.dog.distal, now_.dog.central});
    for (const auto& [label, t] : spec_.times)
      if (same_time(r.time, t, t_end_)) at_[label] = now_;
  }
  std::vector<std::string> history_columns() const override {
    std::vector<std::string> c{"stent_diameter", "stent_dogboning_percent", "stent_centroid_curvature"};
    for (std::size_t k = 0; k < ring_nodes_.size(); ++k) c.push_back(fmt::format("stent_ring_{}_diameter", k));
    return c;
  }
  std::vector<double> history_values() const override {
    std::vector<double> v{now_.diameter, now_.dog.distal, now_.curvature};
    v.insert(v.end(), now_.rings.begin(), now_.rings.end());
    return v;
  }
  std::string checkpoint_name() const override { return "qoi/" + spec_.name; }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    for (const auto& [label, s] : at_) out.put(prefix + "at/" + label, s.pack());
    std::vector<double> flat;
    for (const auto& s : series_) flat.insert(flat.end(), {s.time, s.pressure, s.distal, s.central});
    out.put(prefix + "series", flat);
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    for (const auto& label : labels())
      if (in.has(prefix + "at/" + label)) at_[label] = State::unpack(in.get(prefix + "at/" + label));
    const auto& flat = in.get(prefix + "series");
    series_.clear();
    for (std::size_t i = 0; i + 3 < flat.size(); i += 4) series_.push_back({flat[i], flat[i + 1], flat[i + 2], flat[i + 3]});
  }
  void summarize(Summary& s, const RunEnd&) const override {
    for (const auto& [label, st] : at_) {
      s.set("stent_diameter_" + label, st.diameter, "mm");
      s.set("stent_ring_diameters_" + label, st.rings, "mm");
      s.set("stent_centroid_curvature_" + label, st.curvature, "1/mm");
      if (label != "initial") s.set("stent_bending_moment_max_" + label, st.bending, "N mm");
    }
    s.set("stent_rings", static_cast<double>(ring_nodes_.size()));
    const auto mx = at_.find("max"), af = at_.find("after");
    if (mx != at_.end() && af != at_.end() && mx->second.diameter > 0)
      s.set("recoil_percent", 100.0 * (mx->second.diameter - af->second.diameter) / mx->second.diameter, "%");
    // Dogboning compares end rings with a middle one: it needs three rings at least.
    if (series_.empty() || ring_nodes_.size() < 3) return;
    auto peak = std::max_element(series_.begin(), series_.end(), [](const Sample& a, const Sample& b) { return a.distal < b.distal; });
    s.set("dogboning_percent", peak->distal, "%");
    s.set("dogboning_time", peak->time, "s");
    auto peak_c = std::max_element(series_.begin(), series_.end(), [](const Sample& a, const Sample& b) { return a.central < b.central; });
    s.set("dogboning_central_percent", peak_c->central, "%");
    if (!pressure_) return;
    s.set("dogboning_pressure", peak->pressure, "MPa");
    // 0.8·p_max (p_max: the pressure at the `max` time): the first step pair of the inflation that brackets it.
    const double p08 = 0.8 * pressure_->pressure(t_inflated_);
    double prev_p = 0.0, prev_d = 0.0;  // the undeformed stent: no dogboning at p = 0
    for (const auto& x : series_) {
      if (x.pressure >= p08 && x.pressure > prev_p) {
        const double w = (p08 - prev_p) / (x.pressure - prev_p);
        s.set("dogboning_percent_at_0_8_pmax", prev_d + w * (x.distal - prev_d), "%");
        break;
      }
      prev_p = x.pressure, prev_d = x.distal;
    }
  }

 private:
  struct State {
    double diameter = 0, curvature = 0, bending = 0;
    Dogboning dog;
    std::vector<double> rings;
    std::vector<double> pack() const {
      std::vector<double> v{diameter, curvature, bending, dog.distal, dog.central};
      v.insert(v.end(), rings.begin(), rings.end());
      return v;
    }
    static State unpack(const std::vector<double>& v) {
      State s;
      if (v.size() < 5) throw InputError("checkpoint: a stent_expansion state needs at least 5 values");
      s.diameter = v[0], s.curvature = v[1], s.bending = v[2], s.dog.distal = v[3], s.dog.central = v[4];
      s.rings.assign(v.begin() + 5, v.end());
      return s;
    }
  };
  struct Sample {
    double time, pressure, distal, central;
  };

  std::vector<std::string> labels() const {
    std::vector<std::string> l{"initial"};
    for (const auto& [label, t] : spec_.times) l.push_back(label);
    return l;
  }
  State measure(const Eigen::VectorXd& u) const {
    std::vector<std::vector<Eigen::Vector3d>> pts(ring_nodes_.size());
    for (std::size_t k = 0; k < ring_nodes_.size(); ++k)
      for (int n : ring_nodes_[k]) pts[k].push_back(beam_.position(u, n));
    Eigen::Vector3d lone_axis = Eigen::Vector3d::UnitZ();
    if (ring_nodes_.size() == 1) {
      // The triads' second director points radially outward (stent file contract).
      std::vector<Eigen::Vector3d> radial;
      for (int n : ring_nodes_[0]) radial.push_back(beam_.rotation(n).toRotationMatrix().col(1));
      lone_axis = axis_normal_to(radial);
    }
    const auto rings = measure_rings(pts, lone_axis);
    State s;
    for (const auto& r : rings) s.rings.push_back(r.diameter), s.diameter += r.diameter / static_cast<double>(rings.size());
    s.curvature = max_centroid_curvature(rings);
    s.dog = dogboning(s.rings);
    s.bending = max_bending_moment(beam_, u);
    return s;
  }

  const StentSpec& spec_;
  const beams::BeamTerm& beam_;
  const FollowerPressure* pressure_ = nullptr;
  double t_end_, t_inflated_;
  std::vector<std::vector<int>> ring_nodes_;
  State now_;
  std::map<std::string, State> at_;
  std::vector<Sample> series_;
};

std::unique_ptr<RunObserver> StentSpec::observer(const SceneDesc& scene, const BuiltModel& m) const {
  return std::make_unique<StentExpansion>(*this, m, scene.stepping.t_end);
}

}  // namespace

QoiKind stent_expansion_qoi() {
  return {"stent_expansion", [](ConfigMap& q, SceneReader& r) {
            for (const auto& other : r.scene.qois)
              if (other->unprefixed())
                q.fail("type", fmt::format("stent_expansion writes summary keys without prefix, as '{}' does: one such QoI per scene", other->name));
            auto s = std::make_shared<StentSpec>();
            s->where = fmt::format("{}: {}", q.file().string(), q.dotted_path());
            const BodyDesc& b = r.body(q, "body", true, "stent_expansion");
            s->body = b.name;
            s->pressure = q.string("pressure", "");
            s->times = read_report_times(q, "times", r);
            if (s->times.count("initial")) q.fail("times", "'initial' is reserved for the undeformed stent");
            return s;
          }};
}

}  // namespace stentsim::solver
