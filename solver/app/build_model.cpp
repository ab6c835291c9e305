// The model of a scene (built_model.hpp): bodies first (solid meshes with
// materials per cell tag and fiber frames; beam bodies with their DOF
// numbering and joints), then every condition's own unknowns (multipliers),
// the constraint map, the conditions and the contact pairs, each by its kind
// (solver/io/scene_kinds.hpp). Only what the scene names is allocated.
#include "solver/app/built_model.hpp"

#include <fmt/format.h>

#include <cmath>

#include "common/error.hpp"
#include "common/log.hpp"
#include "solver/app/run_observer.hpp"
#include "solver/io/scene_kinds.hpp"

namespace stentsim::solver {

BuiltModel::BuiltModel() = default;
BuiltModel::~BuiltModel() = default;

namespace {

bool is_volume(CellType t) { return t == CellType::hexahedron || t == CellType::tetra || t == CellType::quadratic_tetra; }

/// Frames per body cell (and, from a fiber field file, the fiber directions per cell) into `spec`.
/// A fibers.vtu (the fibers stage's: volume cells only, in the artery mesh's order) matches the
/// body either cell for cell or volume cell for volume cell (the artery VTU also holds its
/// boundary faces); the cell types and centroids must agree, so a field made for another mesh
/// is an error rather than a silently wrong fiber architecture.
void cell_frames(const BodyDesc& b, const std::filesystem::path& scene, SolidBodySpec& spec) {
  const MeshData& m = b.mesh;
  if (b.frames.kind == FrameSource::Kind::none) return;
  auto& frames = spec.cell_frames;
  frames.assign(m.num_cells(), {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()});
  if (b.frames.kind == FrameSource::Kind::cylindrical) {
    for (std::size_t c = 0; c < m.num_cells(); ++c) {
      Vec3 x = Vec3::Zero();
      const auto conn = m.cell(c);
      for (auto n : conn) x += m.points[static_cast<std::size_t>(n)];
      x /= static_cast<double>(conn.size());
      const Vec3 d = x - b.frames.origin;
      Vec3 er = d - d.dot(b.frames.axis) * b.frames.axis;
      if (er.norm() < 1e-12) throw InputError(fmt::format("{}: body '{}': cell {} lies on the fiber frame axis", scene.string(), b.name, c));
      er.normalize();
      frames[c] = {er, b.frames.axis.cross(er), b.frames.axis};
    }
    return;
  }
  const std::string file = b.frames.file.string();
  const MeshData f = read_vtu(file);
  // Body cell of each file cell.
  std::vector<std::size_t> body_cell;
  if (f.num_cells() == m.num_cells()) {
    for (std::size_t c = 0; c < m.num_cells(); ++c) body_cell.push_back(c);
  } else {
    for (std::size_t c = 0; c < m.num_cells(); ++c)
      if (is_volume(m.cell_types[c])) body_cell.push_back(c);
    if (body_cell.size() != f.num_cells())
      throw InputError(fmt::format("{}: fiber_frames.file {} has {} cells, but body '{}' ({}) has {} cells, {} of them volume cells",
                                   scene.string(), file, f.num_cells(), b.name, b.mesh_source, m.num_cells(), body_cell.size()));
  }
  double extent = 0.0;
  for (const auto& p : m.points) extent = std::max(extent, p.cwiseAbs().maxCoeff());
  auto centroid = [](const MeshData& mesh, std::size_t c) {
    Vec3 x = Vec3::Zero();
    const auto conn = mesh.cell(c);
    for (auto n : conn) x += mesh.points[static_cast<std::size_t>(n)];
    return Vec3(x / static_cast<double>(conn.size()));
  };
  for (std::size_t k = 0; k < f.num_cells(); ++k) {
    const std::size_t c = body_cell[k];
    if (f.cell_types[k] != m.cell_types[c] || (centroid(f, k) - centroid(m, c)).norm() > 1e-6 * std::max(extent, 1.0))
      throw InputError(fmt::format("{}: fiber_frames.file {}: cell {} (type {}, centroid off by {:.3g} mm) does not match cell {} of "
                                   "body '{}' (type {}): the fiber field was made for another mesh",
                                   scene.string(), file, k, static_cast<int>(f.cell_types[k]), (centroid(f, k) - centroid(m, c)).norm(),
                                   c, b.name, static_cast<int>(m.cell_types[c])));
  }
  auto array = [&](const std::string& name, const char* role) -> const DataArray& {
    auto it = f.cell_data.find(name);
    if (it == f.cell_data.end() || it->second.components != 3)
      throw InputError(fmt::format("{}: fiber_frames.file {}: expected a 3-component cell array '{}' ({}){}", scene.string(), file,
                                   name, role,
                                   std::string(role) == "fiber family" ? "; set fiber_frames.fibers: none to build fiber "
                                                                         "directions from the frame and the material angles"
                                                                       : ""));
    return it->second;
  };
  const std::array<std::string, 3> names{b.frames.radial, b.frames.circumferential, b.frames.longitudinal};
  for (int i = 0; i < 3; ++i) {
    const DataArray& a = array(names[static_cast<std::size_t>(i)], "frame");
    for (std::size_t k = 0; k < f.num_cells(); ++k)
      frames[body_cell[k]][static_cast<std::size_t>(i)] = Vec3(a.at(k, 0), a.at(k, 1), a.at(k, 2));
  }
  if (b.frames.fibers.empty()) return;
  spec.fibers_per_cell = static_cast<int>(b.frames.fibers.size());
  std::array<Vec3, kMaxFiberFamilies> zero;
  zero.fill(Vec3::Zero());
  spec.cell_fibers.assign(m.num_cells(), zero);
  for (std::size_t i = 0; i < b.frames.fibers.size(); ++i) {
    const DataArray& a = array(b.frames.fibers[i], "fiber family");
    for (std::size_t k = 0; k < f.num_cells(); ++k) {
      const Vec3 v(a.at(k, 0), a.at(k, 1), a.at(k, 2));
      if (!(std::abs(v.norm() - 1.0) < 1e-6))
        throw InputError(fmt::format("{}: fiber_frames.file {}: '{}' of cell {} has length {:.6g}, expected a unit vector",
                                     scene.string(), file, b.frames.fibers[i], k, v.norm()));
      spec.cell_fibers[body_cell[k]][i] = v;
    }
  }
}

}  // namespace

std::unique_ptr<BuiltModel> build_model(const SceneDesc& scene) {
  auto out = std::make_unique<BuiltModel>();
  Model& model = out->model;
  const std::string file = scene.file.string();
  for (const auto& b : scene.bodies) {
    if (b.beam) {
      // Beam DOFs from the model's DOF map: 9 per Hermite end node, 3 per middle node, 6 per Lagrange node.
      // Rigid joints (stent files): slaves share their master's position and rotation DOFs (rigid_joints.hpp).
      const beams::BeamBodyDefinition& def = b.beam->body;
      const GlobalDof nodal = beams::beam_nodal_dof_count(def);
      GlobalDof count = 0;
      b.beam->number_dofs(0, &count);
      const GlobalDof first = model.dofs.allocate(b.name, count);
      GlobalDof next = 0;
      auto dofs = b.beam->number_dofs(first, &next);
      if (next != first + count) throw std::logic_error("beam DOF numbering does not match its count");
      out->beams[b.name] = &model.add_term<beams::BeamTerm>(b.name, def, std::move(dofs));
      out->beam_desc[b.name] = &*b.beam;
      const std::string joints = b.beam->joint_map.master.empty()
                                     ? (b.beam->joints.empty() ? std::string("no joints")
                                                               : fmt::format("{} joints not coupled (joints: none)", b.beam->joints.size()))
                                     : fmt::format("{} rigid joints, {} DOFs after coupling", b.beam->joints.size(), count);
      const std::string law = def.section.plastic
                                  ? fmt::format("elasto-plastic bending E {:g}, G {:g}, E_ep {:g} MPa, M_y0 {:g} N mm, R {:g} mm",
                                                def.section.plastic->E, def.section.plastic->G, def.section.plastic->E_ep,
                                                def.section.plastic->M_y0, def.section.plastic->radius)
                                  : std::string("elastic");
      out->notes.push_back(fmt::format("beam body {}: {} elements, {} nodal DOFs, {}; {} ({})", b.name, def.elements.size(),
                                       nodal, joints, law, b.beam->source));
      log::info("beam body '{}': {} elements, {} nodes, {} nodal DOFs, {}; {} ({})", b.name, def.elements.size(),
                def.nodes.size(), nodal, joints, law, b.beam->source);
      if (!b.beam->joints.empty() && b.beam->joint_map.master.empty())
        log::warn("beam body '{}': {} joints in the file are not coupled (joints: none)", b.name, b.beam->joints.size());
      continue;
    }
    SolidBodySpec spec;
    spec.name = b.name;
    spec.mesh = b.mesh;
    std::map<int, int> index;
    for (const auto& [tag, mat] : b.materials) {
      index[tag] = static_cast<int>(spec.materials.size());
      spec.materials.push_back(mat);
      out->notes.push_back(fmt::format("body {} tag {}: {}", b.name, tag, mat.describe()));
    }
    spec.cell_material.assign(spec.mesh.num_cells(), -1);
    const DataArray* tags = b.tag_array.empty() ? nullptr : &spec.mesh.cell_data.at(b.tag_array);
    std::size_t solids = 0;
    for (std::size_t c = 0; c < spec.mesh.num_cells(); ++c) {
      if (!is_volume(spec.mesh.cell_types[c])) continue;
      ++solids;
      if (!tags) {
        spec.cell_material[c] = 0;
        continue;
      }
      const int tag = static_cast<int>(std::lround(tags->at(c)));
      auto it = index.find(tag);
      if (it == index.end())
        throw InputError(fmt::format("{}: body '{}': cell {} has {} = {} but no material is given for that tag", file, b.name, c,
                                     b.tag_array, tag));
      spec.cell_material[c] = it->second;
    }
    if (solids == 0) throw InputError(fmt::format("{}: body '{}': the mesh ({}) has no hex8/tet4/tet10 cells", file, b.name, b.mesh_source));
    cell_frames(b, scene.file, spec);
    if (b.frames.kind == FrameSource::Kind::file)
      log::info("body '{}': frames{} per cell from {}", b.name,
                b.frames.fibers.empty() ? std::string(" (fiber directions from the material angles)")
                                        : fmt::format(" and fiber directions ({})", fmt::join(b.frames.fibers, ", ")),
                b.frames.file.string());
    const GlobalDof first = model.dofs.allocate(b.name, 3 * static_cast<GlobalDof>(spec.mesh.points.size()));
    try {
      out->bodies[b.name] = &model.add_term<SolidBody>(std::move(spec), first);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {}", file, e.what()));
    }
    log::info("body '{}': {} nodes, {} solid cells ({})", b.name, b.mesh.points.size(), solids, b.mesh_source);
  }
  // Own unknowns of the conditions (multipliers) before the constraints are sized.
  std::vector<GlobalDof> first_own(scene.conditions.size(), -1);
  for (std::size_t i = 0; i < scene.conditions.size(); ++i) {
    const GlobalDof n = scene.conditions[i]->own_dofs(*out);
    if (n > 0) first_own[i] = model.dofs.allocate(scene.conditions[i]->name, n);
  }
  model.size_constraints();
  for (std::size_t i = 0; i < scene.conditions.size(); ++i) scene.conditions[i]->build(scene, *out, first_own[i]);
  for (const auto& c : scene.contacts) c->build(scene, *out);
  return out;
}

/// The 6 rigid-body modes of the solid nodes, for SA-AMG with 3 equations per node.
/// A model with beam bodies or multipliers has nodes with 9, 6 or 3 beam DOFs and
/// unknowns that are no displacement: a fixed 3-DOF block cannot aggregate them and
/// the solid modes say nothing about them, so such scenes are refused (direct or
/// gmres_ilu solve them). Nodes held in a local frame ("radial only") carry their
/// modes in that frame, as the assembled system does (global_system.hpp).
Eigen::MatrixXd amg_near_null_space(const SceneDesc& scene, const BuiltModel& b) {
  const Model& model = b.model;
  const std::string where = fmt::format("{}: solver.linear.type: gmres_amg", scene.file.string());
  if (!b.beams.empty())
    throw InputError(fmt::format("{} needs 3 displacement DOFs per node, but body '{}' is a beam body (6-9 DOFs per node); "
                                 "use gmres_amg_block (AMG on the largest solid body, LU on the rest), direct or gmres_ilu",
                                 where, b.beams.begin()->first));
  GlobalDof solid = 0;
  std::vector<std::pair<GlobalDof, Vec3>> nodes;
  for (const auto& [name, body] : b.bodies) {
    solid += body->num_dofs();
    for (std::size_t i = 0; i < body->num_nodes(); ++i) nodes.emplace_back(body->dof(i, 0), body->mesh().points[i]);
  }
  if (solid != model.dofs.size())
    throw InputError(fmt::format("{}: the model has {} unknowns that are not solid displacements (e.g. multipliers); "
                                 "use direct or gmres_ilu", where, model.dofs.size() - solid));
  Eigen::MatrixXd modes = model.rigid_body_modes(nodes);
  for (const auto& [d0, x] : nodes)
    if (const Mat3* q = model.constraints.frame(d0)) modes.middleRows<3>(d0) = q->transpose() * modes.middleRows<3>(d0);
  return modes;
}

AmgBlock amg_block(const SceneDesc& scene, const BuiltModel& b) {
  const Model& model = b.model;
  const std::string where = fmt::format("{}: solver.linear.type: gmres_amg_block", scene.file.string());
  const SolidBody* largest = nullptr;
  std::string name;
  for (const auto& [n, body] : b.bodies)
    if (!largest || body->num_dofs() > largest->num_dofs()) largest = body, name = n;
  if (!largest) throw InputError(fmt::format("{} needs a solid body for its AMG block; use direct or gmres_ilu", where));
  if (largest->num_dofs() == model.dofs.size())
    throw InputError(fmt::format("{}: body '{}' holds every unknown, so there is no second block; use gmres_amg", where, name));
  AmgBlock out;
  out.body = name;
  out.begin = largest->first_dof();
  out.end = out.begin + largest->num_dofs();
  std::vector<std::pair<GlobalDof, Vec3>> nodes;
  out.coordinates.resize(static_cast<Eigen::Index>(largest->num_nodes()), 3);
  for (std::size_t i = 0; i < largest->num_nodes(); ++i) {
    nodes.emplace_back(largest->dof(i, 0) - out.begin, largest->mesh().points[i]);
    out.coordinates.row(static_cast<Eigen::Index>(i)) = largest->mesh().points[i].transpose();
  }
  out.modes = model.rigid_body_modes(nodes).topRows(out.end - out.begin);  // rows numbered within the block
  for (const auto& [d0, x] : nodes)
    if (const Mat3* q = model.constraints.frame(d0 + out.begin)) out.modes.middleRows<3>(d0) = q->transpose() * out.modes.middleRows<3>(d0);
  return out;
}

Eigen::MatrixXd amg_node_coordinates(const BuiltModel& b) {
  Eigen::MatrixXd xyz = Eigen::MatrixXd::Zero(b.model.dofs.size() / 3, 3);
  for (const auto& [name, body] : b.bodies)
    for (std::size_t i = 0; i < body->num_nodes(); ++i) xyz.row(body->dof(i, 0) / 3) = body->mesh().points[i].transpose();
  return xyz;
}

}  // namespace stentsim::solver
