// QoIs of one beam node at a time (a stop of the stepper):
//   tip_position        current position (3 numbers) [mm]
//   tip_rotation_angle  angle of the node's rotation from its reference triad,
//                       accumulated over the steps so that it grows past π [rad]
#include <fmt/format.h>

#include "common/error.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/qoi/registry.hpp"
#include "solver/app/run_observer.hpp"
#include "solver/beams/rotation.hpp"

namespace stentsim::solver {
namespace {

class TipQoiSpec : public QoiSpec {
 public:
  bool rotation = false;
  beams::BeamNodeSelector node;
  double time = 0.0;
  std::unique_ptr<RunObserver> observer(const SceneDesc& scene, const BuiltModel& m) const override;
};

class TipQoi : public RunObserver {
 public:
  TipQoi(const TipQoiSpec& spec, const beams::BeamTerm& beam, int node, double t_end)
      : spec_(spec), beam_(beam), node_(node), t_end_(t_end) {}
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    if (spec_.rotation) {
      // Unwrapped after every step, so that the angle is continuous across ±π.
      const Eigen::Quaterniond rel = beam_.rotation(node_) * beam_.body().nodes[static_cast<std::size_t>(node_)].triad.conjugate();
      rotation_ = beams::unwrap_rotation_vector(rel, rotation_);
    }
    if (!same_time(r.time, spec_.time, t_end_)) return;
    if (spec_.rotation) value_ = {rotation_.norm()};
    else {
      const Eigen::Vector3d x = beam_.position(u, node_);
      value_ = {x.x(), x.y(), x.z()};
    }
  }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    out.put(prefix + "rotation", std::span<const double>(rotation_.data(), 3));
    if (!value_.empty()) out.put(prefix + "value", value_);
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    const auto& v = in.get(prefix + "rotation", 3);
    rotation_ = Eigen::Vector3d(v[0], v[1], v[2]);
    if (in.has(prefix + "value")) value_ = in.get(prefix + "value");
  }
  std::string checkpoint_name() const override { return "qoi/" + spec_.name; }
  void summarize(Summary& s, const RunEnd&) const override {
    if (value_.empty()) return;
    if (spec_.rotation) s.set(spec_.name, value_[0], "rad");
    else s.set(spec_.name, value_, "mm");
  }

 private:
  const TipQoiSpec& spec_;
  const beams::BeamTerm& beam_;
  int node_;
  double t_end_;
  Eigen::Vector3d rotation_ = Eigen::Vector3d::Zero();
  std::vector<double> value_;
};

std::unique_ptr<RunObserver> TipQoiSpec::observer(const SceneDesc& scene, const BuiltModel& m) const {
  const int n = beams::select_beam_nodes(*m.beam_desc.at(body), node).at(0);
  return std::make_unique<TipQoi>(*this, m.beam(body), n, scene.stepping.t_end);
}

std::shared_ptr<TipQoiSpec> read_tip_qoi(ConfigMap& q, SceneReader& r, bool rotation) {
  auto s = std::make_shared<TipQoiSpec>();
  s->rotation = rotation;
  const BodyDesc& b = r.body(q, "body", true, rotation ? "tip_rotation_angle" : "tip_position");
  s->body = b.name;
  s->node = beams::read_beam_node_selector(q, "node");
  if (s->node.kind == beams::BeamNodeSelector::Kind::fixations) q.fail("node", "a tip QoI needs one node (first, last or a point)");
  std::vector<int> nodes;
  try {
    nodes = beams::select_beam_nodes(*b.beam, s->node);
  } catch (const InputError& e) {
    q.fail("node", e.what());
  }
  if (nodes.empty()) q.fail("node", fmt::format("selects no end node of beam body '{}' ({})", b.name, s->node.describe()));
  if (nodes.size() != 1) q.fail("node", "selects more than one node");
  s->time = q.quantity("time", units::kTime, r.scene.stepping.t_end);
  r.scene.stepping.stops.push_back(s->time);
  return s;
}

}  // namespace

QoiKind tip_position_qoi() {
  return {"tip_position", [](ConfigMap& q, SceneReader& r) { return read_tip_qoi(q, r, false); }};
}
QoiKind tip_rotation_angle_qoi() {
  return {"tip_rotation_angle", [](ConfigMap& q, SceneReader& r) { return read_tip_qoi(q, r, true); }};
}

}  // namespace stentsim::solver
