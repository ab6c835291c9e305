#include "meshing/generic_artery.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"

namespace stentsim::meshing {

void validate(const GenericArterySpec& s) {
  auto need = [](bool ok, const char* field, const std::string& what) {
    if (!ok) throw InputError(fmt::format("mesh.generic.{}: {}", field, what));
  };
  need(s.length > 0, "length", "must be positive");
  need(s.media_thickness > 0, "media_thickness", "must be positive");
  need(s.adventitia_thickness > 0, "adventitia_thickness", "must be positive");
  need(s.media_thickness + s.adventitia_thickness < s.outer_diameter / 2, "outer_diameter",
       "must exceed twice the wall thickness (media + adventitia)");
  need(s.elements_around >= 8, "elements_around", "must be at least 8");
  need(s.elements_along >= 1, "elements_along", "must be at least 1");
  need(s.elements_media >= 1, "elements_media", "must be at least 1");
  need(s.elements_adventitia >= 1, "elements_adventitia", "must be at least 1");
}

MeshData generic_artery_mesh(const GenericArterySpec& s) {
  validate(s);
  const int nt = s.elements_around, nz = s.elements_along, nm = s.elements_media, na = s.elements_adventitia;
  const int nr = nm + na;
  const double ro = s.outer_diameter / 2, ri = ro - s.media_thickness - s.adventitia_thickness;
  const double rm = ri + s.media_thickness;  // media/adventitia interface
  // Radii of the node shells: uniform within each layer so the interface is a node shell.
  std::vector<double> radius(static_cast<std::size_t>(nr + 1));
  for (int k = 0; k <= nr; ++k)
    radius[static_cast<std::size_t>(k)] = k <= nm ? ri + (rm - ri) * k / nm : rm + (ro - rm) * (k - nm) / na;

  MeshData m;
  auto id = [&](int i, int k, int j) -> std::int64_t {  // around, radial, along
    return (static_cast<std::int64_t>(j) * (nr + 1) + k) * nt + (i % nt);
  };
  for (int j = 0; j <= nz; ++j)
    for (int k = 0; k <= nr; ++k)
      for (int i = 0; i < nt; ++i) {
        const double th = 2 * std::numbers::pi * i / nt;
        const double r = radius[static_cast<std::size_t>(k)];
        m.points.emplace_back(r * std::cos(th), r * std::sin(th), s.length * (static_cast<double>(j) / nz - 0.5));
      }
  std::vector<double> layer, face;
  // Hex8 in VTK order: the bottom face (z_j) runs +r then +theta, so its
  // right-hand normal e_r x e_theta = +e_z points to the top face: J > 0.
  for (int j = 0; j < nz; ++j)
    for (int k = 0; k < nr; ++k)
      for (int i = 0; i < nt; ++i) {
        m.add_cell(CellType::hexahedron, {id(i, k, j), id(i, k + 1, j), id(i + 1, k + 1, j), id(i + 1, k, j),
                                          id(i, k, j + 1), id(i, k + 1, j + 1), id(i + 1, k + 1, j + 1), id(i + 1, k, j + 1)});
        layer.push_back(k < nm ? tags::media : tags::adventitia);
        face.push_back(tags::no_face);
      }
  auto add_face = [&](std::vector<std::int64_t> q, int group) {
    m.add_cell(CellType::quad, q);
    layer.push_back(tags::no_layer);
    face.push_back(group);
  };
  // Faces wound so their right-hand normal points out of the wall (the
  // endothelium's into the lumen, -e_r; the cuts' along -e_z and +e_z).
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nt; ++i) {
      add_face({id(i, 0, j), id(i, 0, j + 1), id(i + 1, 0, j + 1), id(i + 1, 0, j)}, tags::endothelium);
      add_face({id(i, nr, j), id(i + 1, nr, j), id(i + 1, nr, j + 1), id(i, nr, j + 1)}, tags::outer_wall);
    }
  for (int k = 0; k < nr; ++k)
    for (int i = 0; i < nt; ++i) {
      add_face({id(i, k, 0), id(i + 1, k, 0), id(i + 1, k + 1, 0), id(i, k + 1, 0)}, tags::proximal_cut);
      add_face({id(i, k, nz), id(i, k + 1, nz), id(i + 1, k + 1, nz), id(i + 1, k, nz)}, tags::distal_cut);
    }
  m.cell_data[tags::kLayer] = {1, std::move(layer)};
  m.cell_data[tags::kFaceGroup] = {1, std::move(face)};
  m.field_text["units"] = "mm";
  m.field_text["description"] = "generic artery (paper Case 1): media + adventitia, structured hex8";
  return m;
}

void write_generic_artery(const GenericArterySpec& s, const std::string& artery_vtu, Summary& summary) {
  const MeshData m = generic_artery_mesh(s);
  write_vtu(artery_vtu, m);
  std::size_t hex = 0, media = 0;
  for (std::size_t c = 0; c < m.num_cells(); ++c)
    if (m.cell_types[c] == CellType::hexahedron) {
      ++hex;
      if (static_cast<int>(m.cell_data.at(tags::kLayer).at(c)) == tags::media) ++media;
    }
  summary.set("artery_nodes", static_cast<double>(m.points.size()));
  summary.set("artery_dofs", 3.0 * static_cast<double>(m.points.size()));
  summary.set("artery_elements", static_cast<double>(hex));
  summary.set("media_elements", static_cast<double>(media));
  summary.set("adventitia_elements", static_cast<double>(hex - media));
  summary.note("element", "hex8 (structured)");
}

}  // namespace stentsim::meshing
