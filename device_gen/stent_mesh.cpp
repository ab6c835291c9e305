#include "device_gen/stent_mesh.hpp"

#include <fmt/format.h>

namespace stentsim::device_gen {

MeshData stent_to_mesh(const StentModel& s, const StentDesign& d) {
  MeshData m;
  m.points = s.points;
  DataArray e1{3, {}}, e2{3, {}}, e3{3, {}}, kind{1, {}};
  for (std::size_t n = 0; n < s.points.size(); ++n) {
    for (int c = 0; c < 3; ++c) {
      e1.values.push_back(s.triads[n](c, 0));
      e2.values.push_back(s.triads[n](c, 1));
      e3.values.push_back(s.triads[n](c, 2));
    }
    kind.values.push_back(s.node_kind[n]);
  }
  m.point_data["TriadE1"] = std::move(e1);
  m.point_data["TriadE2"] = std::move(e2);
  m.point_data["TriadE3"] = std::move(e3);
  m.point_data["NodeKind"] = std::move(kind);

  DataArray role{1, {}}, type{1, {}}, member{1, {}}, member_kind{1, {}}, ring{1, {}}, radius{1, {}}, material{1, {}},
      direction{3, {}};
  auto beam_data = [&](int r, int t, int mem, int mk, int rg, double rad, int mat, const Eigen::Vector3d& dir) {
    role.values.push_back(r);
    type.values.push_back(t);
    member.values.push_back(mem);
    member_kind.values.push_back(mk);
    ring.values.push_back(rg);
    radius.values.push_back(rad);
    material.values.push_back(mat);
    direction.values.insert(direction.values.end(), {dir.x(), dir.y(), dir.z()});
  };
  for (const auto& e : s.elements) {
    m.add_cell(CellType::quadratic_edge, {e.nodes[0], e.nodes[1], e.nodes[2]});
    const auto& mem = s.members[static_cast<std::size_t>(e.member)];
    beam_data(kStentBeam, kSimoReissnerHermite3, e.member, mem.kind, mem.ring, d.strut_radius, d.material_id,
              Eigen::Vector3d::Zero());
  }
  for (const auto& j : s.joints) {
    m.add_cell(CellType::line, {j[0], j[1]});
    beam_data(kStentJoint, -1, -1, -1, -1, 0.0, -1, Eigen::Vector3d::Zero());
  }
  for (const auto& f : s.fixations) {
    m.add_cell(CellType::vertex, {f.node});
    beam_data(f.axial ? kStentAxialFixation : kStentRadialFixation, -1, -1, -1, -1, 0.0, -1, f.direction);
  }
  m.cell_data["CellRole"] = std::move(role);
  m.cell_data["ElementType"] = std::move(type);
  m.cell_data["Member"] = std::move(member);
  m.cell_data["MemberKind"] = std::move(member_kind);
  m.cell_data["Ring"] = std::move(ring);
  m.cell_data["SectionRadius"] = std::move(radius);
  m.cell_data["MaterialId"] = std::move(material);
  m.cell_data["Direction"] = std::move(direction);
  m.field_text["format"] =
      "stentsim stent 1: CellRole 0 beam (quadratic edge: end, end, middle; ElementType 1 = Simo-Reissner Hermite), "
      "1 joint (line: node pair, rigid rotational coupling, equal positions), 2 radial fixation (vertex: moves only along "
      "Direction), 3 axial fixation (vertex: fixed along Direction); point data TriadE1/E2/E3 (e1 along the beam), "
      "NodeKind 0 end node (9 DOFs) 1 middle node (3 DOFs)";
  m.field_text["units"] = "mm";
  m.field_text["counts"] = fmt::format("{} rings, {} beam elements, {} nodes, {} nodal DOFs before coupling, {} joints, {} fixations",
                                       d.rings, s.elements.size(), s.points.size(), s.nodal_dofs(), s.joints.size(),
                                       s.fixations.size());
  m.field_text["design"] = fmt::format(
      "corrugated rings: {} crowns, crimped diameter {} mm, crown height {} mm, ring pitch {} mm, strut radius {} mm, "
      "{} elements per strut, {} connectors per gap ({}, {} elements each), length {} mm",
      d.crowns, d.crimped_diameter, d.crown_height, d.ring_pitch, d.strut_radius, d.elements_per_strut, d.connectors_per_gap,
      to_string(d.connector_shape), d.elements_per_connector, d.length());
  return m;
}

}  // namespace stentsim::device_gen
