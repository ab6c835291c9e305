// balloon_profile (a straight balloon, solid body): the outer face's nodes
// grouped into stations by their reference position along `axis`; a station's
// diameter is 2·mean distance of its nodes from the axis line. History:
// balloon_diameter_center (the middle station), balloon_diameter_max. Summary:
// balloon_profile_z (station positions along the axis, reference), the profile
// at each labelled time (balloon_profile_diameter_<label>) and at each listed
// inflation pressure of the named pressure condition
// (balloon_profile_diameter_p<MPa>, '.' written '_': linear in pressure between
// the two steps around it), and the balloon's dogboning 100 (r_max − r_center)/r_max,
// its maximum over the inflation (t ≤ the `max` time) with its pressure.
// Curved balloons have no single axis: not supported (an axis is required).
#include <fmt/format.h>

#include <algorithm>
#include <set>

#include "common/error.hpp"
#include "solver/app/body_surfaces.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/qoi/registry.hpp"
#include "solver/app/run_observer.hpp"
#include "solver/io/selection.hpp"

namespace stentsim::solver {
namespace {

class BalloonSpec : public QoiSpec {
 public:
  Selector surface;
  Vec3 origin = Vec3::Zero(), axis = Vec3::UnitZ();
  std::string pressure;
  std::vector<double> pressures;       // MPa
  std::map<std::string, double> times;
  std::unique_ptr<RunObserver> observer(const SceneDesc& scene, const BuiltModel& m) const override;
};

std::string pressure_label(double p) {
  std::string s = fmt::format("p{:g}", p);
  std::replace(s.begin(), s.end(), '.', '_');
  return s;
}

class BalloonProfile : public RunObserver {
 public:
  BalloonProfile(const BalloonSpec& spec, const SceneDesc& scene, const BuiltModel& m)
      : spec_(spec), body_(m.solid(spec.body)), t_end_(scene.stepping.t_end) {
    std::set<std::size_t> nodes;
    for (const auto& f : selected_boundary_faces(scene, fmt::format("qoi '{}'", spec.name), body_, spec.surface))
      for (int i = 0; i < f.count; ++i) nodes.insert(static_cast<std::size_t>(f.nodes[i]));
    std::vector<std::pair<double, std::size_t>> along;
    for (auto n : nodes) along.emplace_back((body_.mesh().points[n] - spec.origin).dot(spec.axis), n);
    std::sort(along.begin(), along.end());
    const double span = along.back().first - along.front().first;
    const double tol = 1e-6 * std::max(span, 1.0);
    for (const auto& [s, n] : along) {
      if (z_.empty() || s - z_.back() > tol) z_.push_back(s), stations_.emplace_back();
      stations_.back().push_back(n);
    }
    if (stations_.size() < 3)
      throw InputError(fmt::format("{}: qoi '{}': the surface has {} stations along the axis; a profile needs at least 3 "
                                   "(is 'axis' the balloon's axis?)",
                                   scene.file.string(), spec.name, stations_.size()));
    if (!spec.pressure.empty()) {
      for (const auto& [name, p] : m.pressures)
        if (name == spec.pressure) pressure_ = p;
      if (!pressure_)
        throw InputError(fmt::format("{}: qoi '{}': 'pressure: {}' names no pressure condition", scene.file.string(),
                                     spec.name, spec.pressure));
    }
    const auto mx = spec.times.find("max");
    t_inflated_ = mx == spec.times.end() ? t_end_ : mx->second;
  }
  void start(const Eigen::VectorXd& u, bool restarted) override {
    now_ = profile(u);
    if (!restarted) previous_ = now_, previous_p_ = 0.0;
  }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    now_ = profile(u);
    for (const auto& [label, t] : spec_.times)
      if (same_time(r.time, t, t_end_)) at_[label] = now_;
    if (r.time > t_inflated_ * (1 + 1e-12)) return;
    const double p = pressure_ ? pressure_->pressure(r.time) : 0.0;
    const double dog = dogboning(now_);
    if (dog > dog_max_) dog_max_ = dog, dog_p_ = p, dog_t_ = r.time;
    if (pressure_) {
      for (double target : spec_.pressures)
        if (!at_p_.count(target) && p >= target && p > previous_p_) {
          const double w = (target - previous_p_) / (p - previous_p_);
          std::vector<double> d(now_.size());
          for (std::size_t i = 0; i < d.size(); ++i) d[i] = previous_[i] + w * (now_[i] - previous_[i]);
          at_p_[target] = d;
        }
      previous_ = now_, previous_p_ = p;
    }
  }
  std::vector<std::string> history_columns() const override { return {"balloon_diameter_center", "balloon_diameter_max"}; }
  std::vector<double> history_values() const override {
    return {now_[now_.size() / 2], *std::max_element(now_.begin(), now_.end())};
  }
  std::string checkpoint_name() const override { return "qoi/" + spec_.name; }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    for (const auto& [label, d] : at_) out.put(prefix + "at/" + label, d);
    for (const auto& [p, d] : at_p_) out.put(prefix + "at_p/" + pressure_label(p), d);
    out.put(prefix + "previous", previous_);
    out.put(prefix + "scalars", std::vector<double>{previous_p_, dog_max_, dog_p_, dog_t_});
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    const auto n = static_cast<long long>(z_.size());
    for (const auto& [label, t] : spec_.times)
      if (in.has(prefix + "at/" + label)) at_[label] = in.get(prefix + "at/" + label, n);
    for (double p : spec_.pressures)
      if (in.has(prefix + "at_p/" + pressure_label(p))) at_p_[p] = in.get(prefix + "at_p/" + pressure_label(p), n);
    previous_ = in.get(prefix + "previous", n);
    const auto& s = in.get(prefix + "scalars", 4);
    previous_p_ = s[0], dog_max_ = s[1], dog_p_ = s[2], dog_t_ = s[3];
  }
  void summarize(Summary& s, const RunEnd&) const override {
    s.set("balloon_profile_z", z_, "mm");
    for (const auto& [label, d] : at_) s.set("balloon_profile_diameter_" + label, d, "mm");
    for (const auto& [p, d] : at_p_) s.set("balloon_profile_diameter_" + pressure_label(p), d, "mm");
    s.set("balloon_dogboning_percent", dog_max_, "%");
    s.set("balloon_dogboning_time", dog_t_, "s");
    if (pressure_) s.set("balloon_dogboning_pressure", dog_p_, "MPa");
  }

 private:
  std::vector<double> profile(const Eigen::VectorXd& u) const {
    std::vector<double> d;
    for (const auto& st : stations_) {
      double acc = 0.0;
      for (auto n : st) {
        const Vec3 r = body_.position(u, n) - spec_.origin;
        acc += (r - r.dot(spec_.axis) * spec_.axis).norm();
      }
      d.push_back(2.0 * acc / static_cast<double>(st.size()));
    }
    return d;
  }
  static double dogboning(const std::vector<double>& d) {
    const double mx = *std::max_element(d.begin(), d.end()), center = d[d.size() / 2];
    return mx > 0 ? 100.0 * (mx - center) / mx : 0.0;
  }

  const BalloonSpec& spec_;
  const SolidBody& body_;
  double t_end_, t_inflated_ = 0;
  const FollowerPressure* pressure_ = nullptr;
  std::vector<double> z_;
  std::vector<std::vector<std::size_t>> stations_;
  std::vector<double> now_, previous_;
  double previous_p_ = 0, dog_max_ = 0, dog_p_ = 0, dog_t_ = 0;
  std::map<std::string, std::vector<double>> at_;
  std::map<double, std::vector<double>> at_p_;
};

std::unique_ptr<RunObserver> BalloonSpec::observer(const SceneDesc& scene, const BuiltModel& m) const {
  return std::make_unique<BalloonProfile>(*this, scene, m);
}

}  // namespace

QoiKind balloon_profile_qoi() {
  return {"balloon_profile", [](ConfigMap& q, SceneReader& r) {
            auto s = std::make_shared<BalloonSpec>();
            s->body = r.body(q, "body", false, "balloon_profile").name;
            s->surface = read_selector(q, "surface");
            if (!q.has("axis")) q.fail("axis", "the balloon's straight axis {origin, direction} is required");
            SceneReader::axis(q, "axis", s->origin, s->axis);
            s->pressure = q.string("pressure", "");
            if (q.has("pressures")) {
              if (s->pressure.empty()) q.fail("pressures", "profiles at pressures need 'pressure: <a pressure condition>'");
              const YAML::Node list = q.node()["pressures"];
              if (!list.IsSequence() || list.size() == 0) q.fail("pressures", "expected a list of pressures in MPa");
              s->pressures = q.numbers("pressures", list.size());  // project units: MPa
              for (double p : s->pressures)
                if (!(p > 0)) q.fail("pressures", "every pressure must be > 0 (MPa)");
            }
            s->times = read_report_times(q, "times", r);
            return s;
          }};
}

}  // namespace stentsim::solver
