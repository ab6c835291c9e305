// Scene kind `beam_to_surface` (solver/contact/beam_to_surface_pair.hpp):
//   - name: stent_balloon
//     type: beam_to_surface
//     beam: stent                       # a beam body
//     solid: balloon                    # a solid body ...
//     surface: {cell_array: {name: FaceTag, value: 2}}   # ... and a selection of its boundary faces
//     penalty: 10 N/mm^2                # ε (paper 2.5)
//     radius: 0.06 mm                   # default: the beam section's radius
//     gauss_points: 6                   # per beam element (paper: 6)
//     smoothing: 0 mm                   # g0 of the C¹ law (0: the linear ⟨−g⟩ law)
//     form: gap_variation               # or potential (contact::BeamContactForm)
//     search_margin: 0.12 mm            # default 2 R
//     max_flips: 8                      # active-set changes of a point within one step
//     times: {max: 1, after: 2}         # optional: summary entries at these times (stops of the stepper)
// Outputs: history.csv contact_<name>_force (Σ w |f|, N) and
// contact_<name>_active_points; per sample point of the beam VTU
// ContactLineLoad_<name> (N/mm, vector), ContactLineLoadMagnitude_<name>,
// ContactGap_<name> (mm; 0 where ContactProjected_<name> is 0: no face within
// reach) from the element's nearest contact Gauss point;
// summary.yaml contact_line_load_max_<name> (N/mm), contact_force_<name> (N),
// contact_mean_penetration_<name> (mm, over the active points) and
// contact_active_points_<name> at the end and, suffixed _<label>, at each of
// `times`; the line load's peak over the run with its time. A beam that starts inside the surface is an
// input error naming the element, the point and the gap (DESIGN.md §8).
#include <fmt/format.h>

#include <cmath>
#include <map>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/app/body_surfaces.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/contact/registry.hpp"
#include "solver/app/contact/strut_overlap.hpp"
#include "solver/app/contact/surface_self_intersection.hpp"
#include "solver/app/run_observer.hpp"
#include "solver/contact/beam_to_surface_pair.hpp"
#include "solver/io/selection.hpp"

namespace stentsim::solver {
namespace {

// Bodies that touch in the initial state (gap 0 up to round-off) are not penetrating.
constexpr double kTouchTolerance = 1e-9;  // mm

using contact::BeamContactPoint;
using contact::BeamToSurfacePair;

struct ContactMeasure {
  double force = 0.0, line_load_max = 0.0, mean_penetration = 0.0;
  int active = 0;
  void put(HistoryArchive& out, const std::string& prefix) const {
    out.put(prefix + "force", force), out.put(prefix + "line_load_max", line_load_max);
    out.put(prefix + "mean_penetration", mean_penetration), out.put(prefix + "active_points", static_cast<double>(active));
  }
  static ContactMeasure get(const HistoryArchive& in, const std::string& prefix) {
    return {in.get_scalar(prefix + "force"), in.get_scalar(prefix + "line_load_max"), in.get_scalar(prefix + "mean_penetration"),
            static_cast<int>(in.get_scalar(prefix + "active_points"))};
  }
};

class BeamToSurfaceOutput : public RunObserver {
 public:
  BeamToSurfaceOutput(const BeamToSurfacePair& pair, std::map<std::string, double> times, double t_end)
      : pair_(pair), times_(std::move(times)), t_end_(t_end) {}
  void start(const Eigen::VectorXd& u, bool restarted) override { now_ = measure(u); }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    now_ = measure(u);
    if (now_.line_load_max > peak_) peak_ = now_.line_load_max, peak_time_ = r.time;
    for (const auto& [label, t] : times_)
      if (same_time(r.time, t, t_end_)) at_[label] = now_;
  }
  std::vector<std::string> history_columns() const override {
    return {fmt::format("contact_{}_force", pair_.name()), fmt::format("contact_{}_active_points", pair_.name())};
  }
  std::vector<double> history_values() const override { return {now_.force, static_cast<double>(now_.active)}; }
  void decorate(std::vector<std::pair<std::string, MeshData>>& meshes, const Eigen::VectorXd& u) const override {
    const auto pts = pair_.evaluate(u);
    const int ng = pair_.settings().gauss_points;
    for (auto& [name, mesh] : meshes) {
      if (name != pair_.beam().name()) continue;
      const std::size_t ne = pair_.beam().body().elements.size();
      const std::size_t per = mesh.points.size() / ne;  // samples + 1 points per element, element-major
      DataArray load{3, {}}, magnitude{1, {}}, gap{1, {}}, projected{1, {}};
      for (std::size_t e = 0; e < ne; ++e)
        for (std::size_t k = 0; k < per; ++k) {
          const double xi = per > 1 ? -1.0 + 2.0 * static_cast<double>(k) / static_cast<double>(per - 1) : 0.0;
          const BeamContactPoint* best = nullptr;
          for (int g = 0; g < ng; ++g) {
            const BeamContactPoint& p = pts[e * static_cast<std::size_t>(ng) + static_cast<std::size_t>(g)];
            if (!best || std::abs(p.xi - xi) < std::abs(best->xi - xi)) best = &p;
          }
          for (int c = 0; c < 3; ++c) load.values.push_back(best->line_load[c]);
          magnitude.values.push_back(best->line_load.norm());
          gap.values.push_back(best->projected ? best->gap : 0.0);  // ContactProjected tells where it is defined
          projected.values.push_back(best->projected ? 1.0 : 0.0);
        }
      mesh.point_data["ContactLineLoad_" + pair_.name()] = load;
      mesh.point_data["ContactLineLoadMagnitude_" + pair_.name()] = magnitude;
      mesh.point_data["ContactGap_" + pair_.name()] = gap;
      mesh.point_data["ContactProjected_" + pair_.name()] = projected;
    }
  }
  std::string checkpoint_name() const override { return "contact/" + pair_.name(); }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    out.put(prefix + "peak", peak_);
    out.put(prefix + "peak_time", peak_time_);
    for (const auto& [label, m] : at_) m.put(out, prefix + "at/" + label + "/");
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    peak_ = in.get_scalar(prefix + "peak");
    peak_time_ = in.get_scalar(prefix + "peak_time");
    for (const auto& [label, t] : times_)
      if (in.has(prefix + "at/" + label + "/force")) at_[label] = ContactMeasure::get(in, prefix + "at/" + label + "/");
  }
  void summarize(Summary& s, const RunEnd&) const override {
    auto put = [&](const ContactMeasure& m, const std::string& suffix) {
      s.set("contact_line_load_max_" + pair_.name() + suffix, m.line_load_max, "N/mm");
      s.set("contact_force_" + pair_.name() + suffix, m.force, "N");
      s.set("contact_mean_penetration_" + pair_.name() + suffix, m.mean_penetration, "mm");
      s.set("contact_active_points_" + pair_.name() + suffix, static_cast<double>(m.active));
    };
    put(now_, "");
    for (const auto& [label, m] : at_) put(m, "_" + label);
    s.set("contact_line_load_peak_" + pair_.name(), peak_, "N/mm");
    s.set("contact_line_load_peak_time_" + pair_.name(), peak_time_, "s");
  }

 private:
  ContactMeasure measure(const Eigen::VectorXd& u) const {
    ContactMeasure m;
    for (const auto& p : pair_.evaluate(u)) {
      if (!p.active) continue;
      ++m.active;
      m.force += p.weight * p.line_load.norm();
      m.line_load_max = std::max(m.line_load_max, p.line_load.norm());
      m.mean_penetration += std::max(-p.gap, 0.0);
    }
    if (m.active) m.mean_penetration /= m.active;
    return m;
  }
  const BeamToSurfacePair& pair_;
  std::map<std::string, double> times_;
  double t_end_;
  ContactMeasure now_;
  std::map<std::string, ContactMeasure> at_;
  double peak_ = 0.0, peak_time_ = 0.0;
};

class BeamToSurfaceSpec : public ContactSpec {
 public:
  std::string beam, solid;
  Selector surface;
  contact::BeamToSurfaceSettings settings;
  bool radius_given = false;
  std::map<std::string, double> times;  // summary labels -> times

  void build(const SceneDesc& scene, BuiltModel& m) const override {
    const std::string file = scene.file.string();
    const beams::BeamTerm& beam_term = m.beam(beam);
    SolidBody& body = m.solid(solid);
    const auto faces = selected_boundary_faces(scene, fmt::format("contact '{}'", name), body, surface);
    contact::BeamToSurfaceSettings s = settings;
    if (!radius_given) {
      s.radius = beam_term.body().section.radius;
      if (!(s.radius > 0))
        throw InputError(fmt::format("{}: contact '{}': beam body '{}' has no section radius; give 'radius'", file, name, beam));
    }
    auto surf = std::make_unique<contact::ContactSurface>(name + ":" + solid, body, faces);
    auto& pair = m.model.add_term<BeamToSurfacePair>(name, beam_term, std::move(surf), s);
    // The initial state must not penetrate (DESIGN.md §8): an input error naming the place.
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.model.dofs.size());
    double min_gap = std::numeric_limits<double>::infinity();
    int projected = 0;
    for (const auto& p : pair.evaluate(zero)) {
      if (p.deep)
        throw InputError(fmt::format("{}: contact '{}': beam '{}' starts deep inside surface '{}' of body '{}': Gauss point {} of element {} "
                                     "at ({:.4f}, {:.4f}, {:.4f}) mm lies farther inside than the search reach; move the bodies apart",
                                     file, name, beam, surface.describe(), solid, p.gauss_point, p.element, p.position.x(),
                                     p.position.y(), p.position.z()));
      if (!p.projected) continue;
      ++projected;
      min_gap = std::min(min_gap, p.gap);
      if (p.gap < -kTouchTolerance)
        throw InputError(fmt::format("{}: contact '{}': beam '{}' starts inside surface '{}' of body '{}': Gauss point {} of element {} "
                                     "at ({:.4f}, {:.4f}, {:.4f}) mm has gap {:.4g} mm (centerline distance {:.4g} mm, radius {:g} mm); "
                                     "move the bodies apart or make the beam's radius smaller",
                                     file, name, beam, surface.describe(), solid, p.gauss_point, p.element, p.position.x(),
                                     p.position.y(), p.position.z(), p.gap, p.gap + s.radius, s.radius));
    }
    const std::string law = fmt::format("{}, {}", s.law.smoothing > 0 ? fmt::format("C1-smoothed law, g0 = {:g} mm", s.law.smoothing)
                                                                       : std::string("linear law"),
                                        s.form == contact::BeamContactForm::potential ? "penalty potential" : "gap variation");
    log::info("contact '{}': beam '{}' on {} faces of '{}' ({}), penalty {:g} N/mm^2, {}, {} Gauss points per element, R = {:g} mm; "
              "initially {} points within reach{}",
              name, beam, faces.size(), solid, contact::face_kind_name(pair.surface().faces()[0].kind), s.law.epsilon, law,
              s.gauss_points, s.radius, projected, projected ? fmt::format(", smallest gap {:.4g} mm", min_gap) : std::string());
    m.notes.push_back(fmt::format("contact {}: beam-to-surface penalty, beam {} on {}, epsilon {:g} N/mm^2, {}, {} Gauss points per "
                                  "element, R {:g} mm, frictionless",
                                  name, beam, solid, s.law.epsilon, law, s.gauss_points, s.radius));
    m.observers.push_back(std::make_unique<BeamToSurfaceOutput>(pair, times, scene.stepping.t_end));
    // Beam–beam contact is not modelled: overlapping struts are detected and warned about (once per beam).
    if (m.overlap_checked_beams.insert(beam).second) m.observers.push_back(make_strut_overlap_check(beam_term, s.radius));
    // Nor is self-contact of the solid: a surface folded through itself is detected and warned about.
    if (m.self_intersection_checked_solids.insert(solid).second)
      m.observers.push_back(make_surface_self_intersection_check(pair.surface(), solid));
  }
};

}  // namespace

ContactKind beam_to_surface_contact() {
  return {"beam_to_surface", [](ConfigMap& c, SceneReader& r) {
            auto s = std::make_shared<BeamToSurfaceSpec>();
            s->beam = r.body(c, "beam", true, "beam_to_surface").name;
            s->solid = r.body(c, "solid", false, "beam_to_surface").name;
            s->surface = read_selector(c, "surface");
            s->settings.law.epsilon = c.quantity("penalty", units::kPressure, std::nullopt, Range::positive());
            s->radius_given = c.has("radius");
            if (s->radius_given) s->settings.radius = c.quantity("radius", units::kLength, std::nullopt, Range::positive());
            s->settings.gauss_points = c.integer("gauss_points", 6, Range::between(1, 32));
            s->settings.law.smoothing = c.quantity("smoothing", units::kLength, 0.0, Range::non_negative());
            s->settings.form = c.choice("form", {"gap_variation", "potential"}, "gap_variation") == "potential"
                                   ? contact::BeamContactForm::potential
                                   : contact::BeamContactForm::gap_variation;
            s->settings.search_margin = c.quantity("search_margin", units::kLength, 0.0, Range::non_negative());
            s->settings.max_flips = c.integer("max_flips", 8, Range::between(1, 1000));
            s->times = read_report_times(c, "times", r);
            return s;
          }};
}

}  // namespace stentsim::solver
