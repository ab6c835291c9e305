#include "solver/app/body_surfaces.hpp"

#include <fmt/format.h>

#include "common/error.hpp"

namespace stentsim::solver {

std::vector<fem::Face> selected_boundary_faces(const SceneDesc& scene, const std::string& who, const SolidBody& body,
                                               const Selector& where) {
  std::vector<bool> active(body.mesh().num_cells());
  for (std::size_t i = 0; i < active.size(); ++i) active[i] = body.cell_material()[i] >= 0;
  auto faces = select_faces(body.mesh(), fem::boundary_faces(body.mesh(), active), where);
  if (faces.empty())
    throw InputError(fmt::format("{}: {}: the surface selection ({}) selects no boundary face of body '{}'", scene.file.string(),
                                 who, where.describe(), body.name()));
  return faces;
}

std::map<std::string, double> read_report_times(ConfigMap& c, const std::string& key, SceneReader& r) {
  std::map<std::string, double> times;
  auto t = c.optional_map(key);
  if (!t) return times;
  for (const auto& kv : t->node()) {
    const std::string label = kv.first.Scalar();
    const double at = t->quantity(label, units::kTime);
    if (!(at > r.scene.stepping.t_start && at <= r.scene.stepping.t_end)) t->fail(label, "must lie inside solver.time");
    times[label] = at;
    r.scene.stepping.stops.push_back(at);
  }
  t->finish();
  return times;
}

}  // namespace stentsim::solver
