// layer_stresses (a layered solid, the artery): per layer, the largest first
// principal Cauchy stress (DESIGN.md §6) as the Gauss-point maximum over the
// layer's cells and as the nodal-averaged variant (the cell-mean tensors
// averaged at each node over the node's cells of that layer, so layer
// interfaces are not smeared, then the largest eigenvalue; the maximum over
// the layer's nodes); the same for the endothelium (the cells that carry an
// endothelium face; nodal: at the endothelium's nodes). At each labelled time:
// max_principal_<layer>_<label>_kpa, ..._nodal_kpa and
// artery_max_displacement_<label>; artery_lumen_face_size (the mean edge of
// the endothelium faces) goes with them because peaks under strut line loads
// are singular and move with the mesh (DESIGN.md §8). History:
// max_principal_<layer>_kpa (Gauss-point maximum) after every step.
//   - name: artery
//     type: layer_stresses
//     body: artery
//     layer_array: Layer
//     layers: {media: 2, adventitia: 3}
//     endothelium: {cell_array: {name: FaceGroup, value: 1}}   # optional
//     times: {prestress: 1, max: 2, after: 3}
#include <fmt/format.h>

#include <Eigen/Eigenvalues>

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

constexpr double kKpa = 1000.0;  // MPa -> kPa

class LayerSpec : public QoiSpec {
 public:
  std::string layer_array;
  std::vector<std::pair<std::string, int>> layers;  // name, tag
  std::optional<Selector> endothelium;
  std::map<std::string, double> times;
  std::unique_ptr<RunObserver> observer(const SceneDesc& scene, const BuiltModel& m) const override;
};

struct Group {
  std::string name;
  std::vector<std::size_t> cells;           // Gauss-point maximum over these
  std::vector<std::size_t> nodes;           // nodal-averaged value at these
  std::vector<std::vector<std::size_t>> node_cells;  // per node: the cells averaged there
};

class LayerStresses : public RunObserver {
 public:
  LayerStresses(const LayerSpec& spec, const SceneDesc& scene, const BuiltModel& m)
      : spec_(spec), body_(m.solid(spec.body)), t_end_(scene.stepping.t_end) {
    const MeshData& mesh = body_.mesh();
    const auto it = mesh.cell_data.find(spec.layer_array);
    if (it == mesh.cell_data.end())
      throw InputError(fmt::format("{}: qoi '{}': body '{}' has no cell array '{}'", scene.file.string(), spec.name,
                                   spec.body, spec.layer_array));
    std::vector<bool> is_volume(mesh.num_cells(), false);
    for (std::size_t c = 0; c < mesh.num_cells(); ++c) is_volume[c] = body_.cell_material()[c] >= 0 && is_3d(mesh.cell_types[c]);
    for (const auto& [name, tag] : spec.layers) {
      std::vector<std::size_t> cells;
      for (std::size_t c = 0; c < mesh.num_cells(); ++c)
        if (is_volume[c] && static_cast<int>(it->second.at(c)) == tag) cells.push_back(c);
      if (cells.empty())
        throw InputError(fmt::format("{}: qoi '{}': no cell of body '{}' has {} = {} (layer '{}')", scene.file.string(),
                                     spec.name, spec.body, spec.layer_array, tag, name));
      groups_.push_back(group(name, cells, {}));
    }
    if (spec.endothelium) {
      const auto faces = selected_boundary_faces(scene, fmt::format("qoi '{}'", spec.name), body_, *spec.endothelium);
      std::set<std::size_t> cells;
      std::set<std::size_t> nodes;
      double edges = 0.0;
      int count = 0;
      for (const auto& f : faces) {
        cells.insert(f.cell);
        const int corners = f.type == CellType::quad ? 4 : 3;
        for (int i = 0; i < f.count; ++i) nodes.insert(static_cast<std::size_t>(f.nodes[i]));
        for (int i = 0; i < corners; ++i, ++count)
          edges += (mesh.points[f.nodes[i]] - mesh.points[f.nodes[(i + 1) % corners]]).norm();
      }
      face_size_ = edges / std::max(1, count);
      groups_.push_back(group("endothelium", {cells.begin(), cells.end()}, {nodes.begin(), nodes.end()}));
    }
  }
  void start(const Eigen::VectorXd& u, bool restarted) override { now_ = measure(u); }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    now_ = measure(u);
    for (const auto& [label, t] : spec_.times)
      if (same_time(r.time, t, t_end_)) at_[label] = now_;
  }
  std::vector<std::string> history_columns() const override {
    std::vector<std::string> c;
    for (const auto& g : groups_) c.push_back(fmt::format("max_principal_{}_kpa", g.name));
    return c;
  }
  std::vector<double> history_values() const override {
    std::vector<double> v;
    for (std::size_t i = 0; i < groups_.size(); ++i) v.push_back(kKpa * now_[2 * i]);
    return v;
  }
  std::string checkpoint_name() const override { return "qoi/" + spec_.name; }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    for (const auto& [label, v] : at_) out.put(prefix + "at/" + label, v);
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    for (const auto& [label, t] : spec_.times)
      if (in.has(prefix + "at/" + label)) at_[label] = in.get(prefix + "at/" + label, static_cast<long long>(2 * groups_.size() + 1));
  }
  void summarize(Summary& s, const RunEnd&) const override {
    for (const auto& [label, v] : at_) {
      for (std::size_t i = 0; i < groups_.size(); ++i) {
        s.set(fmt::format("max_principal_{}_{}_kpa", groups_[i].name, label), kKpa * v[2 * i], "kPa");
        s.set(fmt::format("max_principal_{}_{}_nodal_kpa", groups_[i].name, label), kKpa * v[2 * i + 1], "kPa");
      }
      s.set(fmt::format("{}_max_displacement_{}", spec_.body, label), v.back(), "mm");
    }
    if (spec_.endothelium) s.set(fmt::format("{}_lumen_face_size", spec_.body), face_size_, "mm");
  }

 private:
  static bool is_3d(CellType t) {
    return t == CellType::hexahedron || t == CellType::tetra || t == CellType::quadratic_tetra;
  }
  Group group(const std::string& name, const std::vector<std::size_t>& cells, std::vector<std::size_t> nodes) const {
    Group g;
    g.name = name;
    g.cells = cells;
    std::map<std::size_t, std::vector<std::size_t>> around;
    for (auto c : cells)
      for (auto n : body_.mesh().cell(c)) around[static_cast<std::size_t>(n)].push_back(c);
    if (nodes.empty())
      for (const auto& [n, cs] : around) nodes.push_back(n);
    for (auto n : nodes) {
      g.nodes.push_back(n);
      g.node_cells.push_back(around[n]);
    }
    return g;
  }
  /// Per group: Gauss-point maximum and nodal-averaged maximum [MPa]; then the largest displacement [mm].
  std::vector<double> measure(const Eigen::VectorXd& u) const {
    const SolidCellFields f = body_.cell_fields(u);
    std::vector<double> v;
    for (const auto& g : groups_) {
      double gauss = -std::numeric_limits<double>::infinity(), nodal = gauss;
      for (auto c : g.cells) gauss = std::max(gauss, f.max_principal_gauss[c]);
      for (std::size_t k = 0; k < g.nodes.size(); ++k) {
        Mat3 mean = Mat3::Zero();
        for (auto c : g.node_cells[k]) mean += f.cauchy[c];
        mean /= static_cast<double>(g.node_cells[k].size());
        nodal = std::max(nodal, Eigen::SelfAdjointEigenSolver<Mat3>(mean, Eigen::EigenvaluesOnly).eigenvalues()[2]);
      }
      v.push_back(gauss), v.push_back(nodal);
    }
    double umax = 0.0;
    for (std::size_t n = 0; n < body_.num_nodes(); ++n) umax = std::max(umax, u.segment<3>(body_.dof(n, 0)).norm());
    v.push_back(umax);
    return v;
  }

  const LayerSpec& spec_;
  const SolidBody& body_;
  double t_end_;
  double face_size_ = 0.0;
  std::vector<Group> groups_;
  std::vector<double> now_;
  std::map<std::string, std::vector<double>> at_;
};

std::unique_ptr<RunObserver> LayerSpec::observer(const SceneDesc& scene, const BuiltModel& m) const {
  return std::make_unique<LayerStresses>(*this, scene, m);
}

}  // namespace

QoiKind layer_stresses_qoi() {
  return {"layer_stresses", [](ConfigMap& q, SceneReader& r) {
            auto s = std::make_shared<LayerSpec>();
            s->body = r.body(q, "body", false, "layer_stresses").name;
            s->layer_array = q.string("layer_array", "Layer");
            auto layers = q.map("layers");
            for (const auto& kv : layers.node()) {
              const std::string name = kv.first.Scalar();
              if (name == "endothelium") layers.fail(name, "'endothelium' is the lumen surface: give it as 'endothelium'");
              s->layers.emplace_back(name, layers.integer(name));
            }
            layers.finish();
            if (s->layers.empty()) q.fail("layers", "name at least one layer: {name: tag}");
            if (q.has("endothelium")) s->endothelium = read_selector(q, "endothelium");
            s->times = read_report_times(q, "times", r);
            return s;
          }};
}

}  // namespace stentsim::solver
