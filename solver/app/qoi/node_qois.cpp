// QoIs of a solid body's node selection at a time (a stop of the stepper):
//   mean_radius       mean distance of the nodes from an axis [mm]
//   max_displacement  largest displacement magnitude [mm]
#include <fmt/format.h>

#include "common/error.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/qoi/registry.hpp"
#include "solver/app/run_observer.hpp"
#include "solver/io/selection.hpp"

namespace stentsim::solver {
namespace {

class NodeQoiSpec : public QoiSpec {
 public:
  bool radius = true;  // mean_radius, else max_displacement
  Selector where;
  Vec3 origin = Vec3::Zero(), axis = Vec3::UnitZ();
  double time = 0.0;
  std::unique_ptr<RunObserver> observer(const SceneDesc& scene, const BuiltModel& m) const override;
};

class NodeQoi : public RunObserver {
 public:
  NodeQoi(const NodeQoiSpec& spec, const SolidBody& body, double t_end) : spec_(spec), body_(body), t_end_(t_end) {
    nodes_ = select_nodes(body.mesh(), spec.where);
    if (nodes_.empty()) throw InputError(fmt::format("qoi '{}': the node selection ({}) is empty", spec.name, spec.where.describe()));
  }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    if (!same_time(r.time, spec_.time, t_end_)) return;
    double acc = 0.0;
    for (auto n : nodes_) {
      if (spec_.radius) {
        const Vec3 d = body_.position(u, n) - spec_.origin;
        acc += (d - d.dot(spec_.axis) * spec_.axis).norm();
      } else {
        acc = std::max(acc, u.segment<3>(body_.dof(n, 0)).norm());
      }
    }
    value_ = spec_.radius ? acc / static_cast<double>(nodes_.size()) : acc;
  }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    if (value_) out.put(prefix + "value", *value_);
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    if (in.has(prefix + "value")) value_ = in.get_scalar(prefix + "value");
  }
  std::string checkpoint_name() const override { return "qoi/" + spec_.name; }
  void summarize(Summary& s, const RunEnd&) const override {
    if (value_) s.set(spec_.name, *value_, "mm");
  }

 private:
  const NodeQoiSpec& spec_;
  const SolidBody& body_;
  double t_end_;
  std::vector<std::size_t> nodes_;
  std::optional<double> value_;
};

std::unique_ptr<RunObserver> NodeQoiSpec::observer(const SceneDesc& scene, const BuiltModel& m) const {
  return std::make_unique<NodeQoi>(*this, m.solid(body), scene.stepping.t_end);
}

std::shared_ptr<NodeQoiSpec> read_node_qoi(ConfigMap& q, SceneReader& r, bool radius) {
  auto s = std::make_shared<NodeQoiSpec>();
  s->radius = radius;
  s->body = r.body(q, "body", false, radius ? "mean_radius" : "max_displacement").name;
  s->where = read_selector(q, "nodes");
  if (radius) {
    ConfigMap ax = q.map("axis");
    s->origin = SceneReader::vec3(ax, "origin", Vec3::Zero());
    s->axis = SceneReader::vec3(ax, "direction", Vec3::UnitZ()).normalized();
    ax.finish();
  }
  // Taken at an output step: its time is a stop.
  s->time = q.quantity("time", units::kTime, r.scene.stepping.t_end);
  r.scene.stepping.stops.push_back(s->time);
  return s;
}

}  // namespace

QoiKind mean_radius_qoi() {
  return {"mean_radius", [](ConfigMap& q, SceneReader& r) { return read_node_qoi(q, r, true); }};
}
QoiKind max_displacement_qoi() {
  return {"max_displacement", [](ConfigMap& q, SceneReader& r) { return read_node_qoi(q, r, false); }};
}

}  // namespace stentsim::solver
