// malapposition (a stent's beam body against a solid's surface, the endothelium;
// DESIGN.md §8): per beam Gauss point the gap from the strut surface to the
// surface, g = (signed distance of the centerline point to the closest surface
// point) − R, positive in the lumen (the surface's outward normal, out of the
// artery wall, points into the lumen) and negative where the strut is pressed into
// the wall. A strut is malapposed where g exceeds the strut thickness (`threshold`,
// default 2R: 0.12 mm, the usual OCT rule) and not in contact where g > 0. At each
// labelled time and initially, over the stent's length (Gauss weights × element chord):
// malapposition_max_gap_<label> (mm), malapposition_mean_gap_<label> (mean of
// max(g, 0), mm), malapposed_fraction_<label> and not_in_contact_fraction_<label>
// (label `initial` for the undeformed state).
// Output frames carry StrutGap (mm) at the beam's sample points. Distances are
// exact to the surface's linear triangles (tri6 faces split at their mid-side
// nodes), found through a grid search whose box grows until it holds the nearest
// face, so struts far from the wall are measured as well as those touching it.
//   - name: malapposition
//     type: malapposition
//     body: stent
//     solid: artery
//     surface: {cell_array: {name: FaceTag, value: 1}}
//     radius: 0.06 mm        # default: the beam section's radius
//     threshold: 0.12 mm     # default: 2 radius
//     gauss_points: 6
//     times: {prestress: 1, max: 2, after: 3}
#include <fmt/format.h>

#include <limits>

#include "common/error.hpp"
#include "common/triangle_distance.hpp"
#include "solver/app/body_surfaces.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/qoi/registry.hpp"
#include "solver/app/run_observer.hpp"
#include "solver/beams/element_reference.hpp"
#include "solver/contact/contact_surface.hpp"
#include "solver/contact/face_search.hpp"
#include "solver/io/selection.hpp"

namespace stentsim::solver {
namespace {

class MalappositionSpec : public QoiSpec {
 public:
  std::string solid;
  Selector surface;
  double radius = 0.0, threshold = 0.0;  // 0: from the beam section
  int gauss_points = 6;
  std::map<std::string, double> times;
  bool unprefixed() const override { return true; }
  std::unique_ptr<RunObserver> observer(const SceneDesc& scene, const BuiltModel& m) const override;
};

class Malapposition : public RunObserver {
 public:
  Malapposition(const MalappositionSpec& spec, const SceneDesc& scene, const BuiltModel& m)
      : spec_(spec),
        beam_(m.beam(spec.body)),
        surface_(spec.name + ":" + spec.solid, m.solid(spec.solid),
                 selected_boundary_faces(scene, fmt::format("qoi '{}'", spec.name), m.solid(spec.solid), spec.surface)),
        t_end_(scene.stepping.t_end) {
    radius_ = spec.radius > 0 ? spec.radius : beam_.body().section.radius;
    if (!(radius_ > 0))
      throw InputError(fmt::format("{}: qoi '{}': beam body '{}' has no section radius; give 'radius'", scene.file.string(),
                                   spec.name, spec.body));
    threshold_ = spec.threshold > 0 ? spec.threshold : 2.0 * radius_;
    beams::gauss_legendre(spec.gauss_points, xi_, w_);
  }

  void start(const Eigen::VectorXd& u, bool restarted) override {
    if (!restarted) at_["initial"] = measure(u);
  }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    for (const auto& [label, t] : spec_.times)
      if (same_time(r.time, t, t_end_)) at_[label] = measure(u);
  }
  void decorate(std::vector<std::pair<std::string, MeshData>>& meshes, const Eigen::VectorXd& u) const override {
    for (auto& [name, mesh] : meshes) {
      if (name != spec_.body) continue;
      update(u);
      const std::size_t ne = beam_.body().elements.size();
      const std::size_t per = mesh.points.size() / ne;  // samples + 1 points per element, element-major
      DataArray gap{1, {}};
      for (std::size_t e = 0; e < ne; ++e)
        for (std::size_t k = 0; k < per; ++k) {
          const double xi = per > 1 ? -1.0 + 2.0 * static_cast<double>(k) / static_cast<double>(per - 1) : 0.0;
          gap.values.push_back(signed_distance(beam_.sample(u, e, xi).position) - radius_);
        }
      mesh.point_data["StrutGap"] = gap;
    }
  }
  std::string checkpoint_name() const override { return "qoi/" + spec_.name; }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    for (const auto& [label, m] : at_) out.put(prefix + "at/" + label, m.pack());
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    std::vector<std::string> labels{"initial"};
    for (const auto& [label, t] : spec_.times) labels.push_back(label);
    for (const auto& label : labels)
      if (in.has(prefix + "at/" + label)) at_[label] = Measure::unpack(in.get(prefix + "at/" + label, 4));
  }
  void summarize(Summary& s, const RunEnd&) const override {
    for (const auto& [label, m] : at_) {
      s.set("malapposition_max_gap_" + label, m.max_gap, "mm");
      s.set("malapposition_mean_gap_" + label, m.mean_gap, "mm");
      s.set("malapposed_fraction_" + label, m.malapposed);
      s.set("not_in_contact_fraction_" + label, m.not_in_contact);
    }
    s.set("malapposition_threshold", threshold_, "mm");
  }

 private:
  struct Measure {
    double max_gap = 0, mean_gap = 0, malapposed = 0, not_in_contact = 0;
    std::vector<double> pack() const { return {max_gap, mean_gap, malapposed, not_in_contact}; }
    static Measure unpack(const std::vector<double>& v) { return {v[0], v[1], v[2], v[3]}; }
  };

  void update(const Eigen::VectorXd& u) const {
    surface_.update(u);
    grid_.build(surface_, 0.0);
    Eigen::AlignedBox3d box;
    for (std::size_t i = 0; i < surface_.num_nodes(); ++i) box.extend(surface_.x(static_cast<int>(i)));
    reach_ = box.diagonal().norm();
    start_ = std::max(1e-3 * reach_, 4.0 * radius_);
  }
  /// Signed distance of p to the current surface: positive on the side its normals point to.
  /// The side is judged by the averaged nodal normals interpolated at the closest point (its
  /// barycentric coordinates), the same on both triangles of an edge, so a closest point on an
  /// edge or a vertex of a dent or a bend gets one answer whichever triangle holds it.
  double signed_distance(const Vec3& p) const {
    std::vector<int> faces;
    for (double r = start_;; r *= 2.0) {
      grid_.query(p.array() - r, p.array() + r, faces);
      double best = std::numeric_limits<double>::infinity(), sign = 1.0;
      for (int fi : faces)
        for (const auto& t : contact::linear_triangles(surface_.faces()[static_cast<std::size_t>(fi)])) {
          const Vec3 &a = surface_.x(t[0]), &b = surface_.x(t[1]), &c = surface_.x(t[2]);
          const Vec3 q = closest_on_triangle(p, a, b, c);
          const double d = (p - q).norm();
          if (!(d < best)) continue;
          best = d;
          const Vec3 e0 = b - a, e1 = c - a, e2 = q - a;
          const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1), d20 = e2.dot(e0), d21 = e2.dot(e1);
          const double den = d00 * d11 - d01 * d01;
          const double lb = den > 0 ? (d11 * d20 - d01 * d21) / den : 1.0 / 3, lc = den > 0 ? (d00 * d21 - d01 * d20) / den : 1.0 / 3;
          const Vec3 n = (1 - lb - lc) * surface_.normal(t[0]) + lb * surface_.normal(t[1]) + lc * surface_.normal(t[2]);
          sign = (p - q).dot(n) >= 0.0 ? 1.0 : -1.0;
        }
      // Every face within r of p overlaps the box: a nearest face at most r away is the nearest of all.
      if (best <= r || r > 2.0 * reach_) return sign * best;
    }
  }
  Measure measure(const Eigen::VectorXd& u) const {
    update(u);
    Measure m;
    m.max_gap = -std::numeric_limits<double>::infinity();
    double length = 0.0;
    for (std::size_t e = 0; e < beam_.body().elements.size(); ++e) {
      const double half = 0.5 * (beam_.sample(u, e, 1.0).position - beam_.sample(u, e, -1.0).position).norm();
      for (std::size_t g = 0; g < xi_.size(); ++g) {
        const double gap = signed_distance(beam_.sample(u, e, xi_[g]).position) - radius_;
        const double w = w_[g] * half;
        length += w;
        m.max_gap = std::max(m.max_gap, gap);
        m.mean_gap += w * std::max(gap, 0.0);
        if (gap > threshold_) m.malapposed += w;
        if (gap > 0.0) m.not_in_contact += w;
      }
    }
    if (length > 0) m.mean_gap /= length, m.malapposed /= length, m.not_in_contact /= length;
    return m;
  }

  const MalappositionSpec& spec_;
  const beams::BeamTerm& beam_;
  mutable contact::ContactSurface surface_;  // current positions for the distance search
  mutable contact::FaceSearch grid_;
  mutable double reach_ = 0.0, start_ = 0.0;
  double t_end_, radius_ = 0.0, threshold_ = 0.0;
  std::vector<double> xi_, w_;
  std::map<std::string, Measure> at_;
};

std::unique_ptr<RunObserver> MalappositionSpec::observer(const SceneDesc& scene, const BuiltModel& m) const {
  return std::make_unique<Malapposition>(*this, scene, m);
}

}  // namespace

QoiKind malapposition_qoi() {
  return {"malapposition", [](ConfigMap& q, SceneReader& r) {
            auto s = std::make_shared<MalappositionSpec>();
            s->body = r.body(q, "body", true, "malapposition").name;
            s->solid = r.body(q, "solid", false, "malapposition").name;
            s->surface = read_selector(q, "surface");
            if (q.has("radius")) s->radius = q.quantity("radius", units::kLength, std::nullopt, Range::positive());
            if (q.has("threshold")) s->threshold = q.quantity("threshold", units::kLength, std::nullopt, Range::positive());
            s->gauss_points = q.integer("gauss_points", 6, Range::between(1, 32));
            s->times = read_report_times(q, "times", r);
            if (s->times.empty()) q.fail("times", "give the times to measure at, e.g. {after: 3}");
            return s;
          }};
}

}  // namespace stentsim::solver
