// ring_expansion (beam bodies, examples/stent_ring_expansion.yaml): the mean
// diameter 2·mean(‖(r − o)⊥axis‖) of the selected nodes initially (D_initial),
// at `peak_time` (D_max) and at the end (D_end); recoil_percent =
// 100 (D_max − D_end)/D_max; the largest ‖M_b‖ over all Gauss points at both
// times; the energy balance external work = stored + plastic work (the
// external work of the radial conditions by the trapezoidal rule over the
// steps); the largest reactions left at the end. Summary keys without prefix
// (one ring_expansion QoI per scene).
#include <fmt/format.h>

#include "common/error.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/qoi/beam_measures.hpp"
#include "solver/app/qoi/registry.hpp"
#include "solver/app/run_observer.hpp"

namespace stentsim::solver {
namespace {

class RingSpec : public QoiSpec {
 public:
  beams::BeamNodeSelector node;
  Vec3 origin = Vec3::Zero(), axis = Vec3::UnitZ();
  double peak_time = 0.0;
  bool unprefixed() const override { return true; }
  std::unique_ptr<RunObserver> observer(const SceneDesc& scene, const BuiltModel& m) const override;
};

/// Collects residuals only (reactions).
class ResidualAssembler : public Assembler {
 public:
  explicit ResidualAssembler(Eigen::Index n) : R(Eigen::VectorXd::Zero(n)) {}
  void add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& residual,
           const Eigen::Ref<const Eigen::MatrixXd>&) override {
    for (std::size_t i = 0; i < dofs.size(); ++i)
      if (dofs[i] >= 0) R[dofs[i]] += residual[static_cast<Eigen::Index>(i)];
  }
  bool wants_tangent() const override { return false; }
  Eigen::VectorXd R;
};

class RingExpansion : public RunObserver {
 public:
  RingExpansion(const RingSpec& spec, const BuiltModel& m, double t_end)
      : spec_(spec), m_(m), beam_(m.beam(spec.body)), t_end_(t_end) {
    nodes_ = beams::select_beam_nodes(*m.beam_desc.at(spec.body), spec.node);
  }
  void start(const Eigen::VectorXd& u, bool restarted) override {
    if (!restarted) v_.d0 = diameter(u);
    last_ = radial_snapshot(u);
  }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    const auto now = radial_snapshot(u);
    for (std::size_t k = 0; k < now.size() && k < last_.size(); ++k)
      v_.work += 0.5 * (now[k].first + last_[k].first) * (now[k].second - last_[k].second);
    last_ = now;
    if (same_time(r.time, spec_.peak_time, t_end_)) {
      v_.d_max = diameter(u), v_.mb_peak = max_bending_moment(u);
      v_.direction_reaction_peak = max_direction_reaction(u);
    }
    v_.d_end = diameter(u), v_.mb_end = max_bending_moment(u);
    v_.stored_end = beam_.energy(u), v_.plastic_end = beam_.plastic_work();
    // Reactions at the end (after release every crown reaction vanishes): the multipliers
    // are the forces the conditions apply to the nodes (orthonormal constraint rows), in N.
    v_.radial_force_end = 0.0;
    for (const auto& f : now) v_.radial_force_end = std::max(v_.radial_force_end, std::abs(f.first));
    v_.direction_reaction_end = max_direction_reaction(u);
  }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    out.put(prefix + "D_initial", v_.d0), out.put(prefix + "D_max", v_.d_max), out.put(prefix + "D_end", v_.d_end);
    out.put(prefix + "bending_moment_peak", v_.mb_peak), out.put(prefix + "bending_moment_end", v_.mb_end);
    out.put(prefix + "external_work", v_.work), out.put(prefix + "stored_energy_end", v_.stored_end);
    out.put(prefix + "plastic_work_end", v_.plastic_end);
    out.put(prefix + "radial_force_end", v_.radial_force_end), out.put(prefix + "direction_reaction_end", v_.direction_reaction_end);
    out.put(prefix + "direction_reaction_peak", v_.direction_reaction_peak);
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    v_.d0 = in.get_scalar(prefix + "D_initial"), v_.d_max = in.get_scalar(prefix + "D_max"), v_.d_end = in.get_scalar(prefix + "D_end");
    v_.mb_peak = in.get_scalar(prefix + "bending_moment_peak"), v_.mb_end = in.get_scalar(prefix + "bending_moment_end");
    v_.work = in.get_scalar(prefix + "external_work"), v_.stored_end = in.get_scalar(prefix + "stored_energy_end");
    v_.plastic_end = in.get_scalar(prefix + "plastic_work_end");
    v_.radial_force_end = in.get_scalar(prefix + "radial_force_end");
    v_.direction_reaction_end = in.get_scalar(prefix + "direction_reaction_end");
    v_.direction_reaction_peak = in.get_scalar(prefix + "direction_reaction_peak");
  }
  std::string checkpoint_name() const override { return "qoi/" + spec_.name; }
  void summarize(Summary& s, const RunEnd& end) const override {
    s.set("D_initial", v_.d0, "mm");
    s.set("D_max", v_.d_max, "mm");
    s.set("D_end", v_.d_end, "mm");
    s.set("recoil_percent", v_.d_max > 0 ? 100.0 * (v_.d_max - v_.d_end) / v_.d_max : 0.0, "%");
    s.set("max_bending_moment_peak", v_.mb_peak, "N mm");
    s.set("max_bending_moment_end", v_.mb_end, "N mm");
    s.set("external_work", v_.work, "N mm");
    s.set("stored_energy_end", v_.stored_end, "N mm");
    s.set("plastic_work_end", v_.plastic_end, "N mm");
    s.set("max_radial_condition_force_end", v_.radial_force_end, "N");
    s.set("max_direction_condition_reaction_end", v_.direction_reaction_end, "N");
    s.set("max_direction_condition_reaction_peak", v_.direction_reaction_peak, "N");
    if (end.completed) s.set("max_held_position_reaction_end", held_position_reaction(*end.u, end.time), "N");
    const double W = v_.work;
    s.set("energy_balance_error", W != 0 ? std::abs(W - v_.stored_end - v_.plastic_end) / std::abs(W) : 0.0);
  }

 private:
  double diameter(const Eigen::VectorXd& u) const {
    double acc = 0.0;
    for (int n : nodes_) {
      const Vec3 d = beam_.position(u, n) - spec_.origin;
      acc += (d - d.dot(spec_.axis) * spec_.axis).norm();
    }
    return 2.0 * acc / static_cast<double>(nodes_.size());
  }
  /// max |λ| of the direction conditions (e.g. the stent file's fixations) [N].
  double max_direction_reaction(const Eigen::VectorXd& u) const {
    double r = 0.0;
    for (const auto& [first, count] : m_.direction_multipliers)
      for (GlobalDof d = first; d < first + count; ++d) r = std::max(r, std::abs(u[d]));
    return r;
  }
  double max_bending_moment(const Eigen::VectorXd& u) const { return solver::max_bending_moment(beam_, u); }
  /// Radial force on the body (−λ) and radial displacement of every radial_displacement node,
  /// for the external work (the other conditions hold zero displacement components: no work).
  std::vector<std::pair<double, double>> radial_snapshot(const Eigen::VectorXd& u) const {
    std::vector<std::pair<double, double>> s;
    for (const auto& [name, t] : m_.radial)
      for (std::size_t k = 0; k < t->nodes().size(); ++k) {
        const auto& n = t->nodes()[k];
        double ur = 0.0;
        for (int i = 0; i < 3; ++i) ur += n.pos[i] >= 0 ? n.radial[i] * u[n.pos[i]] : 0.0;
        s.emplace_back(-t->multiplier(u, k), ur);
      }
    return s;
  }
  /// Largest reaction [N] at the beam's position DOFs held in a nodal frame (fix_cylindrical: mirror
  /// planes, axial fix): the beam's residual there in local components. Every element is evaluated
  /// (rank 0 of 1), so every MPI rank gets the same value.
  double held_position_reaction(const Eigen::VectorXd& u, double t) const {
    ResidualAssembler a(u.size());
    beam_.assemble(SystemState{u, t, 0.0}, a);
    double r = 0.0;
    for (const beams::BeamNodeDofs& d : beam_.dofs()) {
      if (d.pos[0] < 0) continue;
      const Mat3* q = m_.model.constraints.frame(d.pos[0]);
      if (!q) continue;
      const Vec3 local = q->transpose() * Vec3(a.R[d.pos[0]], a.R[d.pos[1]], a.R[d.pos[2]]);
      for (int i = 0; i < 3; ++i)
        if (m_.model.constraints.fixed(d.pos[0] + i)) r = std::max(r, std::abs(local[i]));
    }
    return r;
  }

  struct Values {
    double d0 = 0, d_max = 0, d_end = 0, mb_peak = 0, mb_end = 0, work = 0, stored_end = 0, plastic_end = 0;
    double radial_force_end = 0, direction_reaction_end = 0, direction_reaction_peak = 0;
  } v_;
  const RingSpec& spec_;
  const BuiltModel& m_;
  beams::BeamTerm& beam_;
  double t_end_;
  std::vector<int> nodes_;
  std::vector<std::pair<double, double>> last_;
};

std::unique_ptr<RunObserver> RingSpec::observer(const SceneDesc& scene, const BuiltModel& m) const {
  return std::make_unique<RingExpansion>(*this, m, scene.stepping.t_end);
}

}  // namespace

QoiKind ring_expansion_qoi() {
  return {"ring_expansion", [](ConfigMap& q, SceneReader& r) {
            for (const auto& other : r.scene.qois)
              if (other->unprefixed())
                q.fail("type", fmt::format("ring_expansion writes summary keys without prefix, as '{}' does: one such QoI per scene", other->name));
            auto s = std::make_shared<RingSpec>();
            const BodyDesc& b = r.body(q, "body", true, "ring_expansion");
            s->body = b.name;
            s->node = r.beam_nodes(q, "node", b);
            SceneReader::axis(q, "axis", s->origin, s->axis);
            s->peak_time = q.quantity("peak_time", units::kTime);  // D_max; D_end at the end
            if (!(s->peak_time > r.scene.stepping.t_start && s->peak_time <= r.scene.stepping.t_end))
              q.fail("peak_time", "must lie inside solver.time");
            r.scene.stepping.stops.push_back(s->peak_time);
            return s;
          }};
}

}  // namespace stentsim::solver
