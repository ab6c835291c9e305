#include "solver/app/solve.hpp"

#include <fmt/format.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "common/error.hpp"
#include "common/log.hpp"
#include "common/summary.hpp"
#include "solver/assembly/parallel.hpp"
#include "solver/beams/beam_loads.hpp"
#include "solver/beams/beam_output.hpp"
#include "solver/beams/beam_term.hpp"
#include "solver/beams/direction_constraint.hpp"
#include "solver/beams/radial_release.hpp"
#include "solver/beams/rigid_joints.hpp"
#include "solver/beams/rotation.hpp"
#include "solver/io/results_writer.hpp"
#include "solver/io/scene.hpp"
#include "solver/io/solid_output.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "solver/terms/robin_springs.hpp"

namespace stentsim::solver {
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

struct Built {
  Model model;
  std::map<std::string, SolidBody*> bodies;
  std::map<std::string, beams::BeamTerm*> beams;            // beam bodies (scene `beam:`)
  std::map<std::string, const beams::BeamBodyDesc*> beam_desc;
  std::map<std::string, Eigen::Vector3d> tip_rotation;      // accumulated rotation vector per QoI name
  std::vector<std::pair<std::string, FollowerPressure*>> pressures;
  std::map<std::string, beams::RadialDisplacementTerm*> radial;  // radial_displacement conditions by name
  std::vector<std::pair<GlobalDof, GlobalDof>> direction_multipliers;  // (first, count) per direction condition
  std::vector<std::string> notes;
};

/// Cylindrical frame (e_r, e_φ, axis) of a point about an axis.
Mat3 cylindrical_frame(const Vec3& x, const Vec3& origin, const Vec3& axis) {
  const Vec3 d = x - origin;
  Vec3 er = d - d.dot(axis) * axis;
  if (er.norm() < 1e-12) throw InputError("a node lies on the axis; its radial direction is undefined");
  er.normalize();
  Mat3 q;
  q.col(0) = er, q.col(1) = axis.cross(er), q.col(2) = axis;
  return q;
}

// Multiplier DOFs of a direction condition on `nodes` nodes: 2 per "moves only along d" node, 1 per
// "fixed along d" node (the stent file's axial fixation, taken with direction: file).
GlobalDof direction_multiplier_count(const ConditionDesc& c, const beams::BeamBodyDesc& desc, std::size_t nodes) {
  GlobalDof count = 0;
  for (std::size_t k = 0; k < nodes; ++k)
    count += c.direction_from_file && desc.fixations.at(k).axial ? 1 : 2;
  return count;
}

// Clamp, dead point force/moment and "moves only along a direction" on beam nodes.
void add_beam_condition(const SceneDesc& scene, const ConditionDesc& c, Built& out,
                        const std::map<std::string, GlobalDof>& multipliers) {
  Model& model = out.model;
  beams::BeamTerm& beam = *out.beams.at(c.body);
  const beams::BeamBodyDesc& desc = *out.beam_desc.at(c.body);
  const std::string file = scene.file.string();
  const LoadCurve curve = c.curve.empty() ? LoadCurve() : scene.curves.at(c.curve);
  if (c.type == ConditionDesc::Type::release) {
    // The radial condition (read before, scene.cpp) turns into its reactions × curve after `at`.
    const double tol = 1e-9 * std::max(1.0, std::abs(scene.stepping.t_end));
    out.radial.at(c.release_from)->set_release(c.release_at, [curve](double t) { return curve(t); }, tol);
    log::info("condition '{}': '{}' becomes point forces equal to its reactions at t = {:g}, × curve '{}'", c.name,
              c.release_from, c.release_at, c.curve);
    return;
  }
  const auto nodes = beams::select_beam_nodes(desc, c.node);
  log::info("condition '{}': {} node(s) of beam body '{}' ({})", c.name, nodes.size(), c.body, c.node.describe());
  // A condition on a joint acts on its master node; on a slave node it is an error.
  if (!desc.joint_map.master.empty())
    for (int n : nodes) beams::require_master_node(desc.joint_map, n, fmt::format("{}: condition '{}'", file, c.name));
  if (c.type == ConditionDesc::Type::radial_displacement) {
    std::vector<beams::RadialDisplacementTerm::Node> rn;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const int n = nodes[k];
      beams::RadialDisplacementTerm::Node x;
      x.pos = beam.dofs()[static_cast<std::size_t>(n)].pos;
      try {
        x.radial = cylindrical_frame(desc.body.nodes[static_cast<std::size_t>(n)].position, c.axis_origin, c.axis).col(0);
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: condition '{}': node {}: {}", file, c.name, n, e.what()));
      }
      x.multiplier = multipliers.at(c.name) + static_cast<GlobalDof>(k);
      rn.push_back(x);
    }
    out.radial[c.name] = &model.add_term<beams::RadialDisplacementTerm>(c.name, std::move(rn), c.value,
                                                                          [curve](double t) { return curve(t); });
    return;
  }
  if (c.type == ConditionDesc::Type::fix_cylindrical) {
    for (int n : nodes) {
      const beams::BeamNodeDofs& d = beam.dofs()[static_cast<std::size_t>(n)];
      if (d.pos[0] < 0 || d.pos[1] != d.pos[0] + 1 || d.pos[2] != d.pos[0] + 2)
        throw std::logic_error("beam position DOFs are not a consecutive triple");
      const Mat3 q = cylindrical_frame(desc.body.nodes[static_cast<std::size_t>(n)].position, c.axis_origin, c.axis);
      if (const Mat3* old = model.constraints.frame(d.pos[0]); old && (*old - q).norm() > 1e-12)
        throw InputError(fmt::format("{}: condition '{}': node {} already has another nodal frame (another axis)", file,
                                     c.name, n));
      model.constraints.set_frame(d.pos[0], q);
      for (int comp : c.components) model.constraints.fix(d.pos[0] + comp, [](double) { return 0.0; });
    }
    return;
  }
  std::size_t k = 0;
  GlobalDof direction_offset = 0;  // next multiplier of a direction condition
  for (int n : nodes) {
    const beams::BeamNodeDofs& d = beam.dofs()[static_cast<std::size_t>(n)];
    auto fix3 = [&](const std::array<GlobalDof, 3>& dofs) {
      for (GlobalDof g : dofs)
        if (g >= 0) model.constraints.fix(g, [](double) { return 0.0; });
    };
    switch (c.type) {
      case ConditionDesc::Type::clamp:
        // Homogeneous: positions keep X, triads keep Λ₀ (rotation increments 0), tangents keep T₀.
        if (c.clamp_position) fix3(d.pos);
        if (c.clamp_rotation) fix3(d.rot);
        if (c.clamp_tangent) fix3(d.tan);
        break;
      case ConditionDesc::Type::point_force:
      case ConditionDesc::Type::point_moment:
        model.add_term<beams::NodalLoadTerm>(fmt::format("{}@{}", c.name, n),
                                             c.type == ConditionDesc::Type::point_force ? d.pos : d.rot, c.vector,
                                             [curve](double t) { return curve(t); });
        break;
      case ConditionDesc::Type::direction: {
        // The stent file's axial fixation is "fixed along d" (d·u = 0, one multiplier, free to expand
        // radially); the radial ones and a given direction are "moves only along d" (two multipliers).
        // Multipliers are laid out node after node in that order (see direction_multiplier_count).
        Eigen::Vector3d dir = c.vector;
        const bool fixed_along = c.direction_from_file && desc.fixations[k].axial;
        if (c.direction_from_file) dir = desc.fixations[k].direction;
        const GlobalDof m0 = multipliers.at(c.name) + direction_offset;
        const std::string term = fmt::format("{}@{}", c.name, n);
        if (fixed_along) {
          model.add_term<beams::DirectionConstraintTerm>(term, d.pos, dir, m0);
          direction_offset += 1;
        } else {
          model.add_term<beams::DirectionConstraintTerm>(term, d.pos, dir, std::array<GlobalDof, 2>{m0, m0 + 1});
          direction_offset += 2;
        }
        break;
      }
      default:
        throw std::logic_error("solid condition on a beam body");
    }
    ++k;
  }
}

std::unique_ptr<Built> build(const SceneDesc& scene) {
  auto out = std::make_unique<Built>();
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
  // Lagrange multipliers of "moves only along a direction" (their own DOFs, before constraints are sized).
  std::map<std::string, GlobalDof> multipliers;  // condition name -> first multiplier DOF
  for (const auto& c : scene.conditions) {
    if (c.type != ConditionDesc::Type::direction && c.type != ConditionDesc::Type::radial_displacement) continue;
    const auto nodes = beams::select_beam_nodes(*out->beam_desc.at(c.body), c.node);
    const GlobalDof count = c.type == ConditionDesc::Type::direction
                                ? direction_multiplier_count(c, *out->beam_desc.at(c.body), nodes.size())
                                : static_cast<GlobalDof>(nodes.size());
    multipliers[c.name] = model.dofs.allocate(c.name, count);
    if (c.type == ConditionDesc::Type::direction) out->direction_multipliers.emplace_back(multipliers[c.name], count);
  }
  model.size_constraints();
  std::map<GlobalDof, std::string> framed, globally_fixed;  // node first DOF -> condition name
  for (const auto& c : scene.conditions) {
    if (out->beams.count(c.body)) {
      add_beam_condition(scene, c, *out, multipliers);
      continue;
    }
    SolidBody& body = *out->bodies.at(c.body);
    const LoadCurve curve = c.curve.empty() ? LoadCurve() : scene.curves.at(c.curve);
    if (c.type != ConditionDesc::Type::dirichlet) {
      std::vector<bool> active(body.mesh().num_cells());
      for (std::size_t i = 0; i < active.size(); ++i) active[i] = body.cell_material()[i] >= 0;
      auto faces = select_faces(body.mesh(), fem::boundary_faces(body.mesh(), active), c.where);
      if (faces.empty())
        throw InputError(fmt::format("{}: condition '{}': the surface selection ({}) selects no boundary face of body '{}'", file,
                                     c.name, c.where.describe(), c.body));
      log::info("condition '{}': {} faces of body '{}'", c.name, faces.size(), c.body);
      if (c.type == ConditionDesc::Type::pressure)
        out->pressures.emplace_back(c.name, &model.add_term<FollowerPressure>(c.name, body, std::move(faces), c.value, curve));
      else
        model.add_term<RobinSprings>(c.name, body, std::move(faces), c.value);
      continue;
    }
    const auto nodes = select_nodes(body.mesh(), c.where);
    if (nodes.empty())
      throw InputError(fmt::format("{}: condition '{}': the node selection ({}) selects no node of body '{}'", file, c.name,
                                   c.where.describe(), c.body));
    log::info("condition '{}': {} nodes of body '{}'", c.name, nodes.size(), c.body);
    for (auto n : nodes) {
      const GlobalDof d0 = body.dof(n, 0);
      if (c.radial_only) {
        if (globally_fixed.count(d0))
          throw InputError(fmt::format("{}: condition '{}' (radial only) and '{}' (global components) both hold node {} of body '{}'",
                                       file, c.name, globally_fixed[d0], n, c.body));
        const Vec3 d = body.mesh().points[n] - c.axis_origin;
        Vec3 er = d - d.dot(c.axis) * c.axis;
        if (er.norm() < 1e-12)
          throw InputError(fmt::format("{}: condition '{}': node {} lies on the axis; its radial direction is undefined", file, c.name, n));
        er.normalize();
        Mat3 q;
        q.col(0) = er;
        q.col(1) = c.axis.cross(er);
        q.col(2) = c.axis;
        model.constraints.set_frame(d0, q);
        model.constraints.fix(d0 + 1, [](double) { return 0.0; });
        model.constraints.fix(d0 + 2, [](double) { return 0.0; });
        framed[d0] = c.name;
      } else {
        if (framed.count(d0))
          throw InputError(fmt::format("{}: condition '{}' (global components) and '{}' (radial only) both hold node {} of body '{}'",
                                       file, c.name, framed[d0], n, c.body));
        for (int comp : c.components)
          model.constraints.fix(d0 + comp, [v = c.value, curve](double t) { return v * curve(t); });
        globally_fixed[d0] = c.name;
      }
    }
  }
  return out;
}

// ring_expansion QoI (scene.hpp): values kept in one vector so that checkpoints carry them.
enum RingSlot {
  kDmax, kMbPeak, kDend, kMbEnd, kExternalWork, kStoredEnd, kPlasticWorkEnd, kD0,
  kRadialForceEnd,      // max |λ| of the radial_displacement conditions (after release: the ramped point forces)
  kDirectionReactionEnd,  // max |λ| of the direction conditions (e.g. the stent file's axial fixation)
  kRingSlots
};

double ring_diameter(const QoiDesc& q, const Built& b, const Eigen::VectorXd& u) {
  const beams::BeamTerm& beam = *b.beams.at(q.body);
  const auto nodes = beams::select_beam_nodes(*b.beam_desc.at(q.body), q.node);
  double acc = 0.0;
  for (int n : nodes) {
    const Vec3 d = beam.position(u, n) - q.axis_origin;
    acc += (d - d.dot(q.axis) * q.axis).norm();
  }
  return 2.0 * acc / static_cast<double>(nodes.size());
}

/// Largest ‖M_b‖ over every Gauss point of the body at u (committed history).
double max_bending_moment(const beams::BeamTerm& beam, const Eigen::VectorXd& u) {
  double m = 0.0;
  for (std::size_t e = 0; e < beam.body().elements.size(); ++e)
    for (const auto& st : beam.section_states(u, e)) m = std::max(m, st.M.tail<2>().norm());
  return m;
}

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

/// Largest reaction [N] at the beam's position DOFs held in a nodal frame (fix_cylindrical: mirror
/// planes, axial fix): the beam's residual there in local components. Every element is evaluated
/// (rank 0 of 1), so every MPI rank gets the same value.
double held_position_reaction(beams::BeamTerm& beam, const Model& model, const Eigen::VectorXd& u, double t) {
  ResidualAssembler a(u.size());
  beam.assemble(SystemState{u, t, 0.0}, a);
  double m = 0.0;
  for (const beams::BeamNodeDofs& d : beam.dofs()) {
    if (d.pos[0] < 0) continue;
    const Mat3* q = model.constraints.frame(d.pos[0]);
    if (!q) continue;
    const Vec3 local = q->transpose() * Vec3(a.R[d.pos[0]], a.R[d.pos[1]], a.R[d.pos[2]]);
    for (int i = 0; i < 3; ++i)
      if (model.constraints.fixed(d.pos[0] + i)) m = std::max(m, std::abs(local[i]));
  }
  return m;
}

/// Radial force on the body (−λ) and radial displacement of every radial_displacement node,
/// for the external work (the other conditions hold zero displacement components: no work).
std::vector<std::pair<double, double>> radial_snapshot(const Built& b, const Eigen::VectorXd& u) {
  std::vector<std::pair<double, double>> s;
  for (const auto& [name, t] : b.radial)
    for (std::size_t k = 0; k < t->nodes().size(); ++k) {
      const auto& n = t->nodes()[k];
      double ur = 0.0;
      for (int i = 0; i < 3; ++i) ur += n.pos[i] >= 0 ? n.radial[i] * u[n.pos[i]] : 0.0;
      s.emplace_back(-t->multiplier(u, k), ur);
    }
  return s;
}

/// The 6 rigid-body modes of the solid nodes, for SA-AMG with 3 equations per node.
/// A model with beam bodies or multipliers has nodes with 9, 6 or 3 beam DOFs and
/// unknowns that are no displacement: a fixed 3-DOF block cannot aggregate them and
/// the solid modes say nothing about them, so such scenes are refused (direct or
/// gmres_ilu solve them). Nodes held in a local frame ("radial only") carry their
/// modes in that frame, as the assembled system does (global_system.hpp).
Eigen::MatrixXd amg_near_null_space(const SceneDesc& scene, const Built& b) {
  const Model& model = b.model;
  const std::string where = fmt::format("{}: solver.linear.type: gmres_amg", scene.file.string());
  if (!b.beams.empty())
    throw InputError(fmt::format("{} needs 3 displacement DOFs per node, but body '{}' is a beam body (6-9 DOFs per node); "
                                 "use direct or gmres_ilu", where, b.beams.begin()->first));
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

int qoi_beam_node(const QoiDesc& q, const Built& b) {
  return beams::select_beam_nodes(*b.beam_desc.at(q.body), q.node).at(0);
}

/// Accumulates the tip rotation vectors after each converged step (the angle is unwrapped across ±π).
void track_tip_rotations(const SceneDesc& scene, Built& b) {
  for (const auto& q : scene.qois) {
    if (q.type != QoiDesc::Type::tip_rotation_angle) continue;
    const beams::BeamTerm& beam = *b.beams.at(q.body);
    const int n = qoi_beam_node(q, b);
    const Eigen::Quaterniond rel = beam.rotation(n) * beam.body().nodes[static_cast<std::size_t>(n)].triad.conjugate();
    auto [it, fresh] = b.tip_rotation.try_emplace(q.name, Eigen::Vector3d::Zero());
    it->second = beams::unwrap_rotation_vector(rel, it->second);
  }
}

/// Value of a QoI at u (tip_position: 3 numbers).
std::vector<double> qoi_values(const QoiDesc& q, const Built& b, const Eigen::VectorXd& u) {
  if (q.type == QoiDesc::Type::tip_position) {
    const Eigen::Vector3d r = b.beams.at(q.body)->position(u, qoi_beam_node(q, b));
    return {r.x(), r.y(), r.z()};
  }
  if (q.type == QoiDesc::Type::tip_rotation_angle) {
    auto it = b.tip_rotation.find(q.name);
    return {it == b.tip_rotation.end() ? 0.0 : it->second.norm()};
  }
  const SolidBody& body = *b.bodies.at(q.body);
  const auto nodes = select_nodes(body.mesh(), q.where);
  if (nodes.empty()) throw InputError(fmt::format("qoi '{}': the node selection ({}) is empty", q.name, q.where.describe()));
  double acc = 0.0;
  for (auto n : nodes) {
    if (q.type == QoiDesc::Type::mean_radius) {
      const Vec3 d = body.position(u, n) - q.axis_origin;
      acc += (d - d.dot(q.axis) * q.axis).norm();
    } else {
      acc = std::max(acc, u.segment<3>(body.dof(n, 0)).norm());
    }
  }
  return {q.type == QoiDesc::Type::mean_radius ? acc / static_cast<double>(nodes.size()) : acc};
}

}  // namespace

int solve_scene(const std::filesystem::path& scene_yaml, const SolveOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  if (options.verbose) log::set_level(log::Level::debug);
  SceneDesc scene = read_scene(scene_yaml);
  if (options.linear_solver) scene.linear.type = *options.linear_solver;
  const std::filesystem::path out_dir = options.output_dir.empty() ? scene_yaml.parent_path() : options.output_dir;
  auto built = build(scene);
  Model& model = built->model;
  log::info("scene {}: {} DOFs, {} fixed, {} terms", scene_yaml.string(), model.dofs.size(), model.constraints.num_fixed(),
            model.terms.size());

  std::unique_ptr<LinearSolver> linear;
  try {
    linear = make_linear_solver(scene.linear);
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: solver.linear.type: {}", scene_yaml.string(), e.what()));
  }
  if (scene.linear.type == "gmres_amg") linear->set_near_null_space(amg_near_null_space(scene, *built));
  // Ranks: after the linear solver exists (Trilinos initialises MPI when the
  // CLI has not). Every rank holds u; elements are split; rank 0 writes.
  model.rank = parallel::rank();
  model.ranks = parallel::size();
  const bool writes = model.rank == 0;
  if (!writes) log::set_level(log::Level::warn);
  log::info("linear solver: {}; {} MPI rank(s)", linear->describe(), model.ranks);
  if (scene.linear.type == "direct" && model.ranks > 1)
    log::info("direct solver on {} ranks: the assembled matrix is gathered on rank 0 and factored there with "
              "UMFPACK (serial; memory and time of one rank); use gmres_ilu or gmres_amg for large models", model.ranks);

  ResultsWriter writer(writes ? out_dir : std::filesystem::temp_directory_path() /
                                              fmt::format("stentsim_rank{}_{}", model.rank, ::getpid()));
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
  auto frame = [&](double t) {
    std::vector<std::pair<std::string, MeshData>> meshes;
    for (const auto& [name, body] : built->bodies) meshes.emplace_back(name, solid_output(*body, u));
    // Beams: their own VTU per frame (sampled centerline, Radius, triads, section forces) in the same PVD.
    for (const auto& [name, beam] : built->beams) meshes.emplace_back(name, beams::beam_output_mesh(*beam, u));
    writer.write_frame(writer.frames(), t, meshes);
  };
  const std::filesystem::path checkpoint_file = out_dir / "checkpoint.bin";
  Summary summary;
  std::map<std::string, std::vector<double>> qoi;
  long newton_total = 0, linear_total = 0, cuts_total = 0;
  int steps = 0;
  double t_last = scene.stepping.t_start;
  if (options.restart) {
    const std::filesystem::path from = options.restart->empty() ? checkpoint_file : *options.restart;
    const HistoryArchive ck = HistoryArchive::read(from);
    u = Eigen::Map<const Eigen::VectorXd>(ck.get("solver/u", model.dofs.size()).data(), model.dofs.size());
    model.load_history(ck);
    writer.load(ck);
    for (const auto& q : scene.qois)
      if (ck.has("qoi/" + q.name)) qoi[q.name] = ck.get("qoi/" + q.name);
    for (const auto& q : scene.qois)
      if (ck.has("tip_rotation/" + q.name)) {
        const auto& v = ck.get("tip_rotation/" + q.name, 3);
        built->tip_rotation[q.name] = Eigen::Vector3d(v[0], v[1], v[2]);
      }
    const auto& c = ck.get("solver/counters", 4);
    newton_total = static_cast<long>(c[0]), linear_total = static_cast<long>(c[1]), cuts_total = static_cast<long>(c[2]);
    steps = static_cast<int>(c[3]);
    t_last = ck.get_scalar("solver/time");
    scene.stepping.t_start = t_last;
    scene.stepping.dt_initial = ck.get_scalar("solver/next_dt");
    scene.stepping.first_step = steps;
    log::info("restart from {}: step {}, t = {:.6g}, next dt = {:.3g}", from.string(), steps, t_last,
              scene.stepping.dt_initial);
  } else {
    frame(scene.stepping.t_start);
  }
  // ring_expansion: the radial forces and displacements of the last converged state (external work).
  std::vector<std::pair<double, double>> ring_last = radial_snapshot(*built, u);
  for (const auto& q : scene.qois)
    if (q.type == QoiDesc::Type::ring_expansion && !qoi.count(q.name)) {
      qoi[q.name].assign(kRingSlots, 0.0);
      qoi[q.name][kD0] = ring_diameter(q, *built, u);
    }
  std::vector<std::string> columns{"step", "time", "dt", "load_factor", "newton_iterations", "linear_iterations", "step_cuts",
                                   "wall_time_s", "assembly_s", "linear_solve_s"};
  for (const auto& [name, p] : built->pressures) columns.push_back("pressure_" + name);
  if (!options.restart) writer.history_header(columns);
  const LoadCurve* lf = scene.load_factor_curve.empty() ? nullptr : &scene.curves.at(scene.load_factor_curve);
  auto on_step = [&](const StepRecord& r) {
    ++steps;
    t_last = r.time;
    newton_total += r.newton_iterations;
    linear_total += r.linear_iterations;
    cuts_total += r.cuts;
    std::vector<double> row{static_cast<double>(r.step), r.time, r.dt, lf ? (*lf)(r.time) : r.time,
                            static_cast<double>(r.newton_iterations), static_cast<double>(r.linear_iterations),
                            static_cast<double>(r.cuts), r.wall_seconds, r.assembly_seconds, r.linear_seconds};
    for (const auto& [name, p] : built->pressures) row.push_back(p->pressure(r.time));
    writer.history_row(row);
    const double tol = 1e-9 * std::max(1.0, std::abs(scene.stepping.t_end));
    bool at_stop = std::abs(r.time - scene.stepping.t_end) < tol;
    for (double s : scene.stepping.stops) at_stop = at_stop || std::abs(r.time - s) < tol;
    if (r.step % scene.output_every == 0 || at_stop) frame(r.time);
    track_tip_rotations(scene, *built);
    for (const auto& q : scene.qois) {
      if (q.type == QoiDesc::Type::ring_expansion) {
        // External work by trapezoidal rule over the step; D and max ‖M_b‖ at the peak and the end.
        auto& v = qoi[q.name];
        v.resize(kRingSlots, 0.0);
        const auto now = radial_snapshot(*built, u);
        for (std::size_t k = 0; k < now.size() && k < ring_last.size(); ++k)
          v[kExternalWork] += 0.5 * (now[k].first + ring_last[k].first) * (now[k].second - ring_last[k].second);
        ring_last = now;
        const beams::BeamTerm& beam = *built->beams.at(q.body);
        if (std::abs(r.time - q.time) < tol) v[kDmax] = ring_diameter(q, *built, u), v[kMbPeak] = max_bending_moment(beam, u);
        v[kDend] = ring_diameter(q, *built, u), v[kMbEnd] = max_bending_moment(beam, u);
        v[kStoredEnd] = beam.energy(u), v[kPlasticWorkEnd] = beam.plastic_work();
        // Reactions at the end (issue 9: after release every crown reaction vanishes): the multipliers
        // are the forces the conditions apply to the nodes (orthonormal constraint rows), in N.
        v[kRadialForceEnd] = v[kDirectionReactionEnd] = 0.0;
        for (const auto& f : now) v[kRadialForceEnd] = std::max(v[kRadialForceEnd], std::abs(f.first));
        for (const auto& [first, count] : built->direction_multipliers)
          for (GlobalDof d = first; d < first + count; ++d)
            v[kDirectionReactionEnd] = std::max(v[kDirectionReactionEnd], std::abs(u[d]));
        continue;
      }
      if (std::abs(r.time - q.time) < tol) qoi[q.name] = qoi_values(q, *built, u);
    }
    if (scene.checkpoint_every > 0 && r.step % scene.checkpoint_every == 0 && writes) {
      HistoryArchive ck;
      ck.put("solver/u", std::span<const double>(u.data(), static_cast<std::size_t>(u.size())));
      ck.put("solver/time", r.time);
      ck.put("solver/next_dt", r.next_dt);
      ck.put("solver/counters", std::vector<double>{static_cast<double>(newton_total), static_cast<double>(linear_total),
                                                    static_cast<double>(cuts_total), static_cast<double>(steps)});
      for (const auto& [name, v] : qoi) ck.put("qoi/" + name, v);
      for (const auto& [name, v] : built->tip_rotation) ck.put("tip_rotation/" + name, std::span<const double>(v.data(), 3));
      model.save_history(ck);
      writer.save(ck);
      ck.write(checkpoint_file);
      log::info("checkpoint at step {} (t = {:.6g}): {}", r.step, r.time, checkpoint_file.string());
    }
  };
  // The stall message names the load the run could not go beyond (issue 11: "no converged state beyond p = ...").
  scene.stepping.describe_load = [&](double t) {
    std::string d;
    for (const auto& [name, p] : built->pressures) d += fmt::format("{}p = {:.6g} MPa", d.empty() ? "" : ", ", p->pressure(t));
    if (d.empty()) d = fmt::format("t = {:.6g}", t);
    return fmt::format("{} (load factor {:.6g}, t = {:.6g})", d, lf ? (*lf)(t) : t, t);
  };
  GlobalSystem system(model.constraints);
  int status = 0;
  std::string failure;
  try {
    run_load_steps(model, system, *linear, u, scene.stepping, scene.newton, on_step);
  } catch (const ComputeError& e) {
    failure = e.what();
    status = 2;
    // The stalled step's failed attempts are in no step record; the totals count every attempt (issue 11).
    if (const auto* stall = dynamic_cast<const LoadStepStall*>(&e))
      newton_total += stall->newton_iterations, linear_total += stall->linear_iterations, cuts_total += stall->cuts;
    log::error("{}", failure);
    if (std::abs(writer.last_time() - t_last) > 1e-12) frame(t_last);  // the last converged state
    log::error("the last converged state (t = {:.6g}) is in {}", t_last, (out_dir / "results.pvd").string());
  }
  for (const auto& q : scene.qois) {
    if (!qoi.count(q.name)) continue;
    if (q.type == QoiDesc::Type::ring_expansion) {
      const auto& v = qoi[q.name];
      summary.set("D_initial", v[kD0], "mm");
      summary.set("D_max", v[kDmax], "mm");
      summary.set("D_end", v[kDend], "mm");
      summary.set("recoil_percent", v[kDmax] > 0 ? 100.0 * (v[kDmax] - v[kDend]) / v[kDmax] : 0.0, "%");
      summary.set("max_bending_moment_peak", v[kMbPeak], "N mm");
      summary.set("max_bending_moment_end", v[kMbEnd], "N mm");
      summary.set("external_work", v[kExternalWork], "N mm");
      summary.set("stored_energy_end", v[kStoredEnd], "N mm");
      summary.set("plastic_work_end", v[kPlasticWorkEnd], "N mm");
      summary.set("max_radial_condition_force_end", v[kRadialForceEnd], "N");
      summary.set("max_direction_condition_reaction_end", v[kDirectionReactionEnd], "N");
      if (status == 0)
        summary.set("max_held_position_reaction_end", held_position_reaction(*built->beams.at(q.body), model, u, t_last), "N");
      const double W = v[kExternalWork];
      summary.set("energy_balance_error", W != 0 ? std::abs(W - v[kStoredEnd] - v[kPlasticWorkEnd]) / std::abs(W) : 0.0);
      continue;
    }
    if (q.type == QoiDesc::Type::tip_position) summary.set(q.name, qoi[q.name], "mm");
    else summary.set(q.name, qoi[q.name][0], q.type == QoiDesc::Type::tip_rotation_angle ? "rad" : "mm");
  }
  summary.set_text("status", status == 0 ? "completed" : "failed");
  if (!failure.empty()) summary.note("failure", failure);
  summary.set("steps", static_cast<double>(steps));
  summary.set("newton_iterations", static_cast<double>(newton_total));
  summary.set("linear_iterations", static_cast<double>(linear_total));
  summary.set("step_cuts", static_cast<double>(cuts_total));
  summary.set("dofs", static_cast<double>(model.dofs.size()));
  summary.set("final_time", t_last, "s");
  summary.note("scene", scene_yaml.string());
  summary.note("linear_solver", linear->describe());
  for (std::size_t i = 0; i < built->notes.size(); ++i) summary.note(fmt::format("material_{}", i), built->notes[i]);
  // Every rank's own peak memory, gathered on rank 0 (issue 11: a study sums them over ranks);
  // the run's peak_memory_mb is that sum.
  Eigen::VectorXd rank_memory = Eigen::VectorXd::Zero(model.ranks);
  rank_memory[model.rank] = peak_memory_mb_self();
  parallel::sum(rank_memory);
  summary.set("peak_memory_mb_per_rank", std::vector<double>(rank_memory.data(), rank_memory.data() + rank_memory.size()), "MB");
  summary.set_run(std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count(), rank_memory.sum());
  if (writes) summary.write(out_dir / "summary.yaml");
  else std::filesystem::remove_all(std::filesystem::temp_directory_path() / fmt::format("stentsim_rank{}_{}", model.rank, ::getpid()));
  log::info("solve {}: {} steps, {} Newton iterations; results in {}", status == 0 ? "completed" : "FAILED", steps, newton_total,
            out_dir.string());
  return status;
}

}  // namespace stentsim::solver
