// lumen_area (a solid's surface, the endothelium, along a stent's beam body):
// the lumen's cross-section area in fixed planes over the stented segment, as
// IVUS or OCT pullbacks report it (DESIGN.md §8: the minimal lumen area at the end
// of prestress and after). Stations: the planes through each ring's centroid normal
// to the ring-centroid curve and those halfway between neighbouring rings, taken
// in the reference configuration (ring_geometry.hpp; a lone ring's axis is the one
// its radial directions leave out). In each plane the deformed surface is cut
// (plane_section.hpp) and `rays` rays from the station's centre find the nearest
// wall; the area is that of the polygon through the hits, so a cut of another
// part of the vessel farther out does not count. A station where a ray meets no
// wall (the plane leaves the vessel, or the lumen moved off the centre) has no area,
// is left out with a warning and counted (lumen_area_open_stations_<label>). At each labelled
// time and initially: lumen_area_min_<label> (mm²), its position along the
// stations (lumen_area_min_position_<label>, mm from the first), the mean
// (lumen_area_mean_<label>) and the areas of the stations that cut a closed lumen
// (lumen_areas_<label>).
//   - name: lumen
//     type: lumen_area
//     stent: stent
//     body: artery
//     surface: {cell_array: {name: FaceTag, value: 1}}
//     rays: 180
//     times: {prestress: 1, after: 3}
#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "common/error.hpp"
#include "common/log.hpp"
#include "common/plane_section.hpp"
#include "solver/app/body_surfaces.hpp"
#include "solver/app/built_model.hpp"
#include "solver/app/qoi/beam_measures.hpp"
#include "solver/app/qoi/registry.hpp"
#include "solver/app/qoi/ring_geometry.hpp"
#include "solver/app/run_observer.hpp"
#include "solver/contact/contact_surface.hpp"
#include "solver/io/selection.hpp"

namespace stentsim::solver {
namespace {

class LumenAreaSpec : public QoiSpec {
 public:
  std::string stent;
  Selector surface;
  int rays = 180;
  std::map<std::string, double> times;
  bool unprefixed() const override { return true; }
  std::unique_ptr<RunObserver> observer(const SceneDesc& scene, const BuiltModel& m) const override;
};

struct Station {
  Vec3 centre, t, n, b;  // plane point, unit normal, in-plane unit axes
  double position = 0.0; // mm from the first station along the stations
};

class LumenArea : public RunObserver {
 public:
  LumenArea(const LumenAreaSpec& spec, const SceneDesc& scene, const BuiltModel& m)
      : spec_(spec),
        surface_(spec.name + ":" + spec.body, m.solid(spec.body),
                 selected_boundary_faces(scene, fmt::format("qoi '{}'", spec.name), m.solid(spec.body), spec.surface)),
        t_end_(scene.stepping.t_end) {
    const beams::BeamTerm& beam = m.beam(spec.stent);
    const auto rings = stent_ring_nodes(*m.beam_desc.at(spec.stent));
    if (rings.empty())
      throw InputError(fmt::format("{}: qoi '{}': body '{}' has no rings (a stent file's Ring cell array); lumen_area places its "
                                   "planes at the stent's rings",
                                   scene.file.string(), spec.name, spec.stent));
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.model.dofs.size());
    std::vector<std::vector<Vec3>> pts(rings.size());
    std::vector<Vec3> radial;
    for (std::size_t k = 0; k < rings.size(); ++k)
      for (int nd : rings[k]) pts[k].push_back(beam.position(zero, nd));
    if (rings.size() == 1)
      for (int nd : rings[0]) radial.push_back(beam.rotation(nd).toRotationMatrix().col(1));  // stent file: the outward director
    const auto measured = measure_rings(pts, rings.size() == 1 ? axis_normal_to(radial) : Vec3::UnitZ());
    auto add = [&](const Vec3& c, Vec3 t) {
      t.normalize();
      const Vec3 n = t.unitOrthogonal();
      stations_.push_back({c, t, n, t.cross(n), stations_.empty() ? 0.0 : stations_.back().position + (c - stations_.back().centre).norm()});
    };
    for (std::size_t k = 0; k < measured.size(); ++k) {
      if (k > 0) add(0.5 * (measured[k - 1].centroid + measured[k].centroid), measured[k - 1].axis + measured[k].axis);
      add(measured[k].centroid, measured[k].axis);
    }
    for (const auto& f : surface_.faces())
      for (const auto& t : contact::linear_triangles(f)) cells_.push_back(t);
  }

  void start(const Eigen::VectorXd& u, bool restarted) override {
    if (!restarted) at_["initial"] = measure(u);
  }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    for (const auto& [label, t] : spec_.times)
      if (same_time(r.time, t, t_end_)) at_[label] = measure(u);
  }
  std::string checkpoint_name() const override { return "qoi/" + spec_.name; }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    for (const auto& [label, a] : at_) out.put(prefix + "at/" + label, a);
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    std::vector<std::string> labels{"initial"};
    for (const auto& [label, t] : spec_.times) labels.push_back(label);
    for (const auto& label : labels)
      if (in.has(prefix + "at/" + label)) at_[label] = in.get(prefix + "at/" + label, static_cast<long long>(stations_.size()));
  }
  void summarize(Summary& s, const RunEnd&) const override {
    for (const auto& [label, areas] : at_) {
      double lo = std::numeric_limits<double>::infinity(), sum = 0.0, where = 0.0;
      std::vector<double> closed;
      for (std::size_t k = 0; k < areas.size(); ++k) {
        if (!std::isfinite(areas[k])) continue;
        closed.push_back(areas[k]);
        sum += areas[k];
        if (areas[k] < lo) lo = areas[k], where = stations_[k].position;
      }
      s.set("lumen_area_open_stations_" + label, static_cast<double>(areas.size() - closed.size()));
      if (closed.empty()) {
        s.note("lumen_area_" + label, "no station's plane cuts a closed lumen");
        continue;
      }
      s.set("lumen_area_min_" + label, lo, "mm^2");
      s.set("lumen_area_min_position_" + label, where, "mm");
      s.set("lumen_area_mean_" + label, sum / static_cast<double>(closed.size()), "mm^2");
      s.set("lumen_areas_" + label, closed, "mm^2");
    }
    s.set("lumen_area_stations", static_cast<double>(stations_.size()));
  }

 private:
  /// Area per station at u (NaN where a ray meets no wall).
  std::vector<double> measure(const Eigen::VectorXd& u) const {
    surface_.update(u);
    MeshData mesh;
    for (std::size_t i = 0; i < surface_.num_nodes(); ++i) mesh.points.push_back(surface_.x(static_cast<int>(i)));
    for (const auto& c : cells_) mesh.add_cell(CellType::triangle, std::vector<std::int64_t>(c.begin(), c.end()));
    std::vector<double> areas;
    int open = 0;
    for (const Station& st : stations_) {
      const auto segs = plane_cut(mesh, st.centre, st.t, st.n, st.b);
      std::vector<Eigen::Vector2d> hits;
      for (int k = 0; k < spec_.rays; ++k) {
        const double a = 2.0 * std::numbers::pi * k / spec_.rays;
        const Eigen::Vector2d dir(std::cos(a), std::sin(a));
        const double r = ray_hit(segs, dir);
        if (!std::isfinite(r)) break;
        hits.push_back(r * dir);
      }
      if (hits.size() < static_cast<std::size_t>(spec_.rays)) {
        areas.push_back(std::numeric_limits<double>::quiet_NaN());
        ++open;
        continue;
      }
      double area = 0.0;  // shoelace over the hit polygon
      for (std::size_t k = 0; k < hits.size(); ++k) {
        const auto& p = hits[k];
        const auto& q = hits[(k + 1) % hits.size()];
        area += 0.5 * (p.x() * q.y() - p.y() * q.x());
      }
      areas.push_back(area);
    }
    if (open > 0)
      log::warn("qoi '{}': {} of {} stations cut no closed lumen around their centre (left out of the areas)", spec_.name, open,
                stations_.size());
    return areas;
  }

  const LumenAreaSpec& spec_;
  mutable contact::ContactSurface surface_;
  double t_end_;
  std::vector<Station> stations_;
  std::vector<std::array<int, 3>> cells_;  // the surface's linear triangles, surface-local nodes
  std::map<std::string, std::vector<double>> at_;
};

std::unique_ptr<RunObserver> LumenAreaSpec::observer(const SceneDesc& scene, const BuiltModel& m) const {
  return std::make_unique<LumenArea>(*this, scene, m);
}

}  // namespace

QoiKind lumen_area_qoi() {
  return {"lumen_area", [](ConfigMap& q, SceneReader& r) {
            auto s = std::make_shared<LumenAreaSpec>();
            s->stent = r.body(q, "stent", true, "lumen_area").name;
            s->body = r.body(q, "body", false, "lumen_area").name;
            s->surface = read_selector(q, "surface");
            s->rays = q.integer("rays", 180, Range::between(16, 100000));
            s->times = read_report_times(q, "times", r);
            return s;
          }};
}

}  // namespace stentsim::solver
