// Surface-to-surface (balloon–artery) penalty contact (DESIGN.md §5 Contact):
// the consistent tangent against central differences on curved, non-matching
// patches (quad4 slave on tri6 and quad4 masters), and the contact patch test
// of two blocks with non-matching interface meshes, whose error comes from the
// element-based integration and falls with the Gauss points per slave face;
// under the validation label, Hertz's cylinder and the rigid flat punch.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <numbers>

#include <Eigen/QR>

#include "solver/assembly/constraints.hpp"
#include "solver/assembly/global_system.hpp"
#include "solver/contact/surface_to_surface_pair.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/nonlinear/load_stepper.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "tests/solver/dense_assembler.hpp"
#include "tests/solver/fd_check.hpp"

namespace stentsim::solver {
namespace {

using contact::ContactSurface;
using contact::SurfaceToSurfacePair;
using contact::SurfaceToSurfaceSettings;
using contact::SurfaceContactNode;

class ResidualOnly : public test::DenseAssembler {
 public:
  using DenseAssembler::DenseAssembler;
  bool wants_tangent() const override { return false; }
};

SolidBodySpec solid_spec(const std::string& name, MeshData mesh) {
  SolidBodySpec spec;
  spec.name = name;
  spec.mesh = std::move(mesh);
  Material m;
  m.name = "nh";
  m.matrix = CoupledNeoHooke::from_young_poisson(1.0, 0.3);
  spec.materials = {m};
  spec.cell_material.assign(spec.mesh.num_cells(), 0);
  return spec;
}

/// Boundary faces whose every node satisfies `pred` (reference positions).
std::vector<fem::Face> faces_where(const SolidBody& body, const std::function<bool(const Vec3&)>& pred) {
  std::vector<fem::Face> out;
  for (const auto& f : fem::boundary_faces(body.mesh())) {
    bool all = true;
    for (int i = 0; i < f.count; ++i) all = all && pred(body.mesh().points[static_cast<std::size_t>(f.nodes[static_cast<std::size_t>(i)])]);
    if (all) out.push_back(f);
  }
  return out;
}

/// Smallest parametric distance of the hit points' master coordinates to their master face's edges.
[[maybe_unused]] double min_edge_distance(const SurfaceToSurfacePair& pair, const contact::SurfaceContactState& st, int& hits) {
  double dmin = 1e9;
  hits = 0;
  for (const auto& p : st.points) {
    if (p.master_face < 0) continue;
    ++hits;
    const auto kind = pair.master().faces()[static_cast<std::size_t>(p.master_face)].kind;
    const double a = p.master_xi[0], b = p.master_xi[1];
    const double d = kind == contact::FaceKind::quad4 ? std::min(1 - std::abs(a), 1 - std::abs(b)) : std::min({a, b, 1 - a - b});
    dmin = std::min(dmin, d);
  }
  return dmin;
}

#ifndef STENTSIM_S2S_VALIDATION
// ---------------------------------------------------------------------------
// 1. FD tangent of the term alone on curved non-matching patches.

enum class MasterKind { tri6, quad4 };

void fd_tangent_check(MasterKind kind, int gauss) {
  // Slave: a 3 x 3 x 1 hex8 plate, its bottom curved z = −0.03 + 0.15 r² (quad4).
  MeshData ms = box_hex8(3, 3, 1, 1.0, 1.0, 0.3);
  for (auto& p : ms.points) {
    p.x() -= 0.5, p.y() -= 0.5;
    p.x() += 0.013, p.y() -= 0.021;  // non-matching with the master's lines
    p.z() += -0.03 + 0.15 * (p.x() * p.x() + p.y() * p.y());
  }
  // Master: a 4 x 4 x 1 block (hex8, or tet10 with tri6 faces), top z = 0.05 r² + a wave.
  MeshData mm = box_hex8(4, 4, 1, 1.4, 1.4, 0.3);
  if (kind == MasterKind::tri6) mm = tet4_to_tet10(hex8_to_tet4(mm));
  for (auto& p : mm.points) {
    p.x() -= 0.7, p.y() -= 0.7, p.z() -= 0.3;
    p.z() += 0.05 * (p.x() * p.x() + p.y() * p.y()) + 0.01 * std::sin(3 * p.x()) * std::cos(2 * p.y());
  }
  const SolidBody slave_body(solid_spec("slave", ms), 0);
  const SolidBody master_body(solid_spec("master", mm), slave_body.num_dofs());
  const GlobalDof n = slave_body.num_dofs() + master_body.num_dofs();
  auto slave = std::make_unique<ContactSurface>("balloon", slave_body, faces_where(slave_body, [](const Vec3& p) {
    return p.z() < 0.1 + 0.15 * (p.x() * p.x() + p.y() * p.y()) - 0.03 - 0.05; }));
  auto master = std::make_unique<ContactSurface>("endothelium", master_body, faces_where(master_body, [](const Vec3& p) { return p.z() > -0.05; }));
  ASSERT_EQ(slave->faces().size(), 9u);
  ASSERT_EQ(master->faces().size(), kind == MasterKind::tri6 ? 32u : 16u);
  SurfaceToSurfaceSettings set;
  set.law.epsilon = 5.0;
  set.gauss_points = gauss;
  set.search_margin = 0.3;
  SurfaceToSurfacePair pair("s2s", std::move(slave), std::move(master), set);

  // A deterministic, non-smooth perturbation of every node.
  Eigen::VectorXd u(n);
  for (GlobalDof i = 0; i < n; ++i) u(i) = 0.01 * std::sin(1.7 * static_cast<double>(i) + 0.3 * static_cast<double>(i * i % 7));
  const SystemState st{u};
  pair.begin_step(st);
  test::DenseAssembler a(n);
  pair.assemble(st, a);
  const auto cs = pair.evaluate(u);
  int active = 0, inactive = 0;
  for (const auto& nd : cs.nodes) (nd.active ? active : inactive) += 1;
  int hits = 0;
  const double edge = min_edge_distance(pair, cs, hits);
  auto residual = [&](const Eigen::VectorXd& v) {
    ResidualOnly r(n);
    pair.assemble(SystemState{v}, r);
    return Eigen::VectorXd(r.r);
  };
  // Central differences in the DOFs of the two surfaces' nodes (the term touches no others).
  std::vector<GlobalDof> cols;
  for (const ContactSurface* s : {&pair.slave(), &pair.master()})
    for (std::size_t i = 0; i < s->num_nodes(); ++i)
      for (int c = 0; c < 3; ++c) cols.push_back(s->dof(static_cast<int>(i), c));
  Eigen::MatrixXd kfd = Eigen::MatrixXd::Zero(n, n);
  const double h = 1e-6;
  for (GlobalDof c : cols) {
    Eigen::VectorXd up = u, um = u;
    up(c) += h, um(c) -= h;
    kfd.col(c) = (residual(up) - residual(um)) / (2 * h);
  }
  const double err = test::rel_error(a.k, kfd);
  const double asym = (a.k - a.k.transpose()).norm() / a.k.norm();
  std::printf("FD tangent, quad4 slave on %s master, %dx%d Gauss points: %d active / %d inactive slave nodes, %d of %zu points hit, "
              "closest master edge %.2e (parametric): rel. error %.2e, asymmetry %.1e, |K| %.3e\n",
              kind == MasterKind::tri6 ? "tri6" : "quad4", gauss, gauss, active, inactive, hits, cs.points.size(), edge, err, asym,
              a.k.norm());
  EXPECT_GE(active, 4);
  EXPECT_GE(inactive, 1);
  EXPECT_LT(edge, 0.05);   // points near master face edges take part
  EXPECT_GT(edge, 1e-5);   // but not so near that the FD step crosses one
  EXPECT_LT(err, 1e-6);
  EXPECT_LT(asym, 1e-10);  // the Hessian of one potential
  // The residual is the gradient of Π: the slave and master forces balance.
  EXPECT_LT((cs.force_on_slave + cs.force_on_master).norm(), 1e-10 * cs.force_on_slave.norm());
  EXPECT_GT(cs.force_on_slave.z(), 0.0);  // the master pushes the slave up
  EXPECT_LT((a.r - residual(u)).norm(), 1e-13 * a.r.norm());
  // Two ranks, each its fixed part of the slave nodes, add up to the whole.
  test::DenseAssembler split(n);
  for (int rank = 0; rank < 2; ++rank) pair.assemble(SystemState{u, 0.0, 0.0, rank, 2}, split);
  EXPECT_LT((split.k - a.k).norm(), 1e-13 * a.k.norm());
  EXPECT_LT((split.r - a.r).norm(), 1e-13 * a.r.norm());
}

TEST(SolverContactS2S, TangentMatchesFiniteDifferencesTri6Master) { fd_tangent_check(MasterKind::tri6, 4); }
TEST(SolverContactS2S, TangentMatchesFiniteDifferencesQuad4Master) { fd_tangent_check(MasterKind::quad4, 3); }

// The matrix pattern a slave node reserves couples it to the master faces its
// Gauss points hit, not to every candidate of the search: a flat 1 x 1 slave
// plate over a 2.8 x 2.8 master with a search margin of 0.6 has candidate faces
// out to |x| = 1.2, but its points (straight down) hit only |x|, |y| <= 0.7.
TEST(SolverContactS2S, ReservesTheBlocksOfHitMasterFacesOnly) {
  MeshData ms = box_hex8(4, 4, 1, 1.0, 1.0, 0.2);
  for (auto& p : ms.points) p.x() -= 0.5, p.y() -= 0.5, p.z() += 0.01;  // 0.01 above the master
  MeshData mm = box_hex8(8, 8, 1, 2.8, 2.8, 0.3);
  for (auto& p : mm.points) p.x() -= 1.4, p.y() -= 1.4, p.z() -= 0.3;
  const SolidBody slave_body(solid_spec("slave", ms), 0);
  const SolidBody master_body(solid_spec("master", mm), slave_body.num_dofs());
  const GlobalDof n = slave_body.num_dofs() + master_body.num_dofs();
  auto slave = std::make_unique<ContactSurface>("balloon", slave_body, faces_where(slave_body, [](const Vec3& p) { return p.z() < 0.02; }));
  auto master = std::make_unique<ContactSurface>("endothelium", master_body, faces_where(master_body, [](const Vec3& p) { return p.z() > -1e-9; }));
  SurfaceToSurfaceSettings set;
  set.law.epsilon = 5.0;
  set.search_margin = 0.6;
  SurfaceToSurfacePair pair("s2s", std::move(slave), std::move(master), set);
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  pair.begin_step(SystemState{u});
  Constraints constraints(n);
  GlobalSystem system(constraints);
  system.begin(u, true);
  pair.assemble(SystemState{u}, system);
  system.finish();
  const CsrMatrix& k = system.matrix();
  int hit_columns = 0, far_columns = 0;
  for (std::size_t i = 0; i < pair.slave().num_nodes(); ++i)
    for (int c = 0; c < 3; ++c) {
      const auto row = static_cast<std::size_t>(pair.slave().dof(static_cast<int>(i), c));
      for (auto e = k.row_ptr[row]; e < k.row_ptr[row + 1]; ++e) {
        const GlobalDof col = k.cols[static_cast<std::size_t>(e)];
        if (col < slave_body.num_dofs()) continue;
        const Vec3& x = mm.points[static_cast<std::size_t>((col - slave_body.num_dofs()) / 3)];
        (std::max(std::abs(x.x()), std::abs(x.y())) <= 0.7 + 1e-9 ? hit_columns : far_columns) += 1;
      }
    }
  std::printf("slave rows: %d entries in master columns under the slave, %d beyond it\n", hit_columns, far_columns);
  EXPECT_GT(hit_columns, 0);
  EXPECT_EQ(far_columns, 0);
}

// ---------------------------------------------------------------------------
// 2. Contact patch test: two unit blocks, laterally on rollers (uniform stress),
// the lower one's bottom fixed, the upper one pressed by a follower pressure P
// through a non-matching interface; the nodal pressures p_j should equal P.

struct PatchResult {
  double max_error = 0.0, mean_error = 0.0;
  double force_error = 0.0;
};

PatchResult patch_test(int slave_n, int master_n, int gauss) {
  constexpr double P = 0.1, eps = 5.0, overlap = P / eps;
  Model model;
  MeshData lower = box_hex8(master_n, master_n, 2, 1.0, 1.0, 1.0);
  MeshData upper = box_hex8(slave_n, slave_n, 2, 1.0, 1.0, 1.0);
  for (auto& p : upper.points) p.z() += 1.0 - overlap;  // start in contact: a free upper block would have no stiffness
  auto& lb = model.add_term<SolidBody>(solid_spec("lower", lower), model.dofs.allocate("lower", 3 * static_cast<GlobalDof>(lower.points.size())));
  auto& ub = model.add_term<SolidBody>(solid_spec("upper", upper), model.dofs.allocate("upper", 3 * static_cast<GlobalDof>(upper.points.size())));
  const double zi = 1.0 - overlap;
  auto slave = std::make_unique<ContactSurface>("upper bottom", ub, faces_where(ub, [&](const Vec3& p) { return p.z() < zi + 1e-9; }));
  auto master = std::make_unique<ContactSurface>("lower top", lb, faces_where(lb, [](const Vec3& p) { return p.z() > 1 - 1e-9; }));
  SurfaceToSurfaceSettings set;
  set.law.epsilon = eps;
  set.gauss_points = gauss;
  set.search_margin = 0.2;
  auto& pair = model.add_term<SurfaceToSurfacePair>("s2s", std::move(slave), std::move(master), set);
  model.add_term<FollowerPressure>("p", ub, faces_where(ub, [&](const Vec3& p) { return p.z() > zi + 1 - 1e-9; }), P, LoadCurve::ramp(0, 1));
  model.size_constraints();
  auto zero = [](double) { return 0.0; };
  for (const SolidBody* b : {&lb, &ub})
    for (std::size_t i = 0; i < b->num_nodes(); ++i) {
      const Vec3 p = b->mesh().points[i];
      if (p.x() < 1e-9 || p.x() > 1 - 1e-9) model.constraints.fix(b->dof(i, 0), zero);
      if (p.y() < 1e-9 || p.y() > 1 - 1e-9) model.constraints.fix(b->dof(i, 1), zero);
      if (b == &lb && p.z() < 1e-9)
        for (int c = 0; c < 3; ++c) model.constraints.fix(b->dof(i, c), zero);
    }
  GlobalSystem sys(model.constraints);
  auto linear = make_linear_solver({});
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
  StepperSettings st;
  st.dt_initial = 0.5;
  st.dt_max = 0.5;
  NewtonSettings ns;
  ns.residual_tolerance = 1e-11;
  run_load_steps(model, sys, *linear, u, st, ns, [](const StepRecord&) {});
  const auto cs = pair.evaluate(u);
  PatchResult r;
  int count = 0;
  for (const auto& nd : cs.nodes) {
    EXPECT_TRUE(nd.active);
    const double e = std::abs(nd.current_pressure - P) / P;
    r.max_error = std::max(r.max_error, e);
    r.mean_error += e;
    ++count;
  }
  r.mean_error /= count;
  r.force_error = (cs.force_on_slave - Vec3(0, 0, P)).norm() / P;  // unit interface area, unchanged on rollers
  return r;
}

TEST(SolverContactS2S, PatchTestNonMatchingBlocks) {
  // Bounds measured (the printed numbers) with a margin of about 3.
  struct Case {
    int slave_n, master_n, gauss;
    double bound;
  };
  // Measured max errors: slave 4x4 on 3x3: 6.1e-3 (2x2), 9.6e-3 (4x4), 1.3e-3 (8x8), 1.6e-4 (16x16);
  // slave 3x3 on 4x4: 7.6e-3, 6.3e-3, 1.1e-3. Segment-based integration would give ~1e-8.
  const Case cases[] = {{4, 3, 2, 0.02}, {4, 3, 4, 0.025}, {4, 3, 8, 0.004}, {4, 3, 16, 5e-4},
                        {3, 4, 2, 0.02}, {3, 4, 4, 0.02}, {3, 4, 8, 0.004}};
  for (const Case& c : cases) {
    const PatchResult r = patch_test(c.slave_n, c.master_n, c.gauss);
    std::printf("patch test: slave %dx%d on master %dx%d, %dx%d Gauss points per slave face: nodal pressure error max %.3e, "
                "mean %.3e; total force error %.1e\n", c.slave_n, c.slave_n, c.master_n, c.master_n, c.gauss, c.gauss,
                r.max_error, r.mean_error, r.force_error);
    EXPECT_LT(r.force_error, 1e-8);
    EXPECT_LT(r.max_error, c.bound);
  }
}

#else  // STENTSIM_S2S_VALIDATION
// ---------------------------------------------------------------------------
// 3. Plane-strain contact benchmarks against closed forms: a block (X >= 0 half
// model, one element thick, u_Y = 0, bottom fixed, E = 1, ν = 0.3) indented by
// a body 1000x stiffer whose contact face is the slave. Both closed forms are
// for a half-space, E* = E / (1 − ν²); the block is 3 mm deep and wide, at
// least 20 contact half-widths. P is the contact force per length of the
// whole (mirrored) model, measured from the pair.

/// Node coordinates 0..L: n_fine uniform elements of size h, then growing by `growth` up to L.
std::vector<double> graded(double h, int n_fine, double growth, double L) {
  std::vector<double> x{0.0};
  for (int i = 0; i < n_fine; ++i) x.push_back(x.back() + h);
  double d = h;
  while (x.back() < L - 1e-12) {
    d *= growth;
    x.push_back(std::min(L, x.back() + d));
    if (L - x.back() < 0.5 * d) x.back() = L;
  }
  return x;
}

constexpr double kE = 1.0, kNu = 0.3, kL = 3.0, kDepth = 3.0, kThick = 0.05;
const double kEs = kE / (1 - kNu * kNu);

/// The block [0, L] x [−t, 0] x [−D, 0], element size h near the origin on top.
MeshData graded_block(double h, int fine_x, int fine_z) {
  const std::vector<double> gx = graded(h, fine_x, 1.15, kL), gz = graded(h, fine_z, 1.15, kDepth);
  const int nx = static_cast<int>(gx.size()) - 1, nz = static_cast<int>(gz.size()) - 1;
  MeshData block = box_hex8(nx, 1, nz, 1.0, 1.0, 1.0);
  for (auto& p : block.points) {
    p.x() = gx[static_cast<std::size_t>(std::lround(p.x() * nx))];
    p.z() = -gz[static_cast<std::size_t>(nz - std::lround(p.z() * nz))];
    p.y() = (p.y() - 1.0) * kThick;
  }
  return block;
}

struct Indentation {
  double force = 0.0;  // P [N/mm], whole model
  std::vector<SurfaceContactNode> nodes;
};

/// Presses `indenter` (its nodes where `driven` holds move down by `depth`) into the block.
Indentation indent(const MeshData& block, const MeshData& indenter, const std::function<bool(const Vec3&)>& slave_face,
                   const std::function<bool(const Vec3&)>& driven, double depth, double epsilon) {
  Model model;
  auto& bb = model.add_term<SolidBody>(solid_spec("block", block), model.dofs.allocate("block", 3 * static_cast<GlobalDof>(block.points.size())));
  SolidBodySpec is = solid_spec("indenter", indenter);
  is.materials[0].matrix = CoupledNeoHooke::from_young_poisson(1000 * kE, kNu);
  auto& ib = model.add_term<SolidBody>(is, model.dofs.allocate("indenter", 3 * static_cast<GlobalDof>(indenter.points.size())));
  auto slave = std::make_unique<ContactSurface>("indenter", ib, faces_where(ib, slave_face));
  auto master = std::make_unique<ContactSurface>("block top", bb, faces_where(bb, [](const Vec3& p) { return p.z() > -1e-9; }));
  SurfaceToSurfaceSettings set;
  set.law.epsilon = epsilon;
  set.gauss_points = 4;
  set.search_margin = 0.02;
  auto& pair = model.add_term<SurfaceToSurfacePair>("s2s", std::move(slave), std::move(master), set);
  model.size_constraints();
  auto zero = [](double) { return 0.0; };
  for (std::size_t i = 0; i < bb.num_nodes(); ++i) {
    const Vec3 p = bb.mesh().points[i];
    model.constraints.fix(bb.dof(i, 1), zero);
    if (p.x() < 1e-9) model.constraints.fix(bb.dof(i, 0), zero);
    if (p.z() < -kDepth + 1e-9) model.constraints.fix(bb.dof(i, 0), zero), model.constraints.fix(bb.dof(i, 2), zero);
  }
  for (std::size_t i = 0; i < ib.num_nodes(); ++i) {
    const Vec3 p = ib.mesh().points[i];
    model.constraints.fix(ib.dof(i, 1), zero);
    if (std::abs(p.x()) < 1e-9) model.constraints.fix(ib.dof(i, 0), zero);
    if (driven(p)) model.constraints.fix(ib.dof(i, 2), [depth](double time) { return -depth * time; });
  }
  GlobalSystem sys(model.constraints);
  auto linear = make_linear_solver({});
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dofs.size());
  StepperSettings st;
  st.dt_initial = 0.1;  // the first contact from a line of zero gap takes a short step
  st.dt_max = 0.25;
  run_load_steps(model, sys, *linear, u, st, {}, [](const StepRecord&) {});
  const auto cs = pair.evaluate(u);
  return {2.0 * cs.force_on_slave.z() / kThick, cs.nodes};
}

// 3a. Hertz: a cylinder of radius R, a = sqrt(4 P R / (π E*)), p0 = 2 P / (π a),
// at a/R <= 0.05 with slave and master elements <= a/20 over ±2a and ε >= 100 E*/a.
// a and p0 come from a least-squares fit p² = p0² (1 − x²/a²) of the slave nodes'
// pressures, not from the last node in contact.
TEST(SolverContactS2SValidation, HertzCylinderPlaneStrain) {
  constexpr double R = 1.0, h = 0.002, delta = 0.0045, epsilon = 5000.0;
  const MeshData block = graded_block(h, 60, 25);  // uniform to x = 0.12 (2.5 a), z = −0.05
  // Ring sector about Y through (0, ·, R), ±0.12 rad (its edge 7 µm above the block at
  // the final indentation): (r cos φ, r sin φ, z) -> (r sin φ, −z, R − r cos φ).
  MeshData ring = ring_sector_hex8(0.8 * R, R, 0.24, kThick, 4, 120, 1);
  for (auto& p : ring.points) p = Vec3(p.y(), -p.z(), R - p.x());
  auto radius = [&](const Vec3& p) { return std::hypot(p.x(), p.z() - R); };
  const Indentation r = indent(block, ring, [&](const Vec3& p) { return radius(p) > R - 1e-9; },
                               [&](const Vec3& p) { return radius(p) < 0.8 * R + 1e-9; }, delta, epsilon);
  const double P = r.force;
  const double a_h = std::sqrt(4 * P * R / (std::numbers::pi * kEs)), p0_h = 2 * P / (std::numbers::pi * a_h);
  // Least squares p² = c0 + c1 x² over the nodes with p² above 20 % of the peak (the edge is smeared over an element).
  double pmax = 0.0;
  for (const auto& n : r.nodes) pmax = std::max(pmax, n.current_pressure);
  Eigen::MatrixXd A(0, 2);
  Eigen::VectorXd b(0);
  for (const auto& n : r.nodes) {
    if (n.current_pressure * n.current_pressure < 0.2 * pmax * pmax) continue;
    A.conservativeResize(A.rows() + 1, 2);
    b.conservativeResize(b.rows() + 1);
    A.row(A.rows() - 1) << 1.0, n.position.x() * n.position.x();
    b(b.rows() - 1) = n.current_pressure * n.current_pressure;
  }
  ASSERT_GE(A.rows(), 20);
  const Eigen::Vector2d c = A.colPivHouseholderQr().solve(b);
  const double p0 = std::sqrt(c(0)), a = std::sqrt(-c(0) / c(1));
  std::printf("Hertz plane strain: P = %.4e N/mm, a = %.5f (Hertz %.5f, %+.2f %%), p0 = %.4e (Hertz %.4e, %+.2f %%), "
              "a/R = %.4f, h = a/%.1f, eps a/E* = %.0f, peak nodal pressure %.4e, %ld nodes fitted\n",
              P, a, a_h, 100 * (a / a_h - 1), p0, p0_h, 100 * (p0 / p0_h - 1), a_h / R, a_h / h, epsilon * a_h / kEs, pmax,
              static_cast<long>(A.rows()));
  // The resolution: the test is only meaningful inside it.
  EXPECT_LE(a_h / R, 0.05);
  EXPECT_GE(a_h / h, 20.0);
  EXPECT_GE(epsilon * a_h / kEs, 100.0);
  EXPECT_GE(kL, 20 * a_h);
  EXPECT_NEAR(a / a_h, 1.0, 0.05);
  EXPECT_NEAR(p0 / p0_h, 1.0, 0.05);
}

// 3b. A rigid flat punch of half-width a: p(x) = P / (π sqrt(a² − x²)) for |x| < a,
// singular at the corners; compared within 5 % for |x| <= 0.8 a.
TEST(SolverContactS2SValidation, RigidFlatPunchPlaneStrain) {
  constexpr double a = 0.1, h = a / 40, delta = 0.002, epsilon = 1e4;
  const MeshData block = graded_block(h, 60, 20);  // uniform to x = 1.5 a
  MeshData punch = box_hex8(40, 1, 10, 1.0, 1.0, 1.0);
  for (auto& p : punch.points) p = Vec3(a * p.x(), (p.y() - 1.0) * kThick, 0.25 * a * p.z());
  const Indentation r = indent(block, punch, [](const Vec3& p) { return p.z() < 1e-9; },
                               [&](const Vec3& p) { return p.z() > 0.25 * a - 1e-9; }, delta, epsilon);
  const double P = r.force;
  double worst = 0.0;
  int compared = 0;
  for (const auto& n : r.nodes) {
    const double x = n.position.x();
    if (n.position.y() < -1e-9 || x > 0.8 * a * (1 + 1e-3)) continue;  // one row of nodes, |x| <= 0.8 a (current positions)
    const double exact = P / (std::numbers::pi * std::sqrt(a * a - x * x));
    const double err = n.current_pressure / exact - 1;
    std::printf("  x/a = %.3f  p = %.5e  closed form %.5e  %+.2f %%\n", x / a, n.current_pressure, exact, 100 * err);
    worst = std::max(worst, std::abs(err));
    ++compared;
  }
  std::printf("Rigid flat punch: P = %.4e N/mm, a = %.3f, h = a/%.0f, eps a/E* = %.0f, largest error for |x| <= 0.8 a: "
              "%.2f %% over %d nodes\n", P, a, a / h, epsilon * a / kEs, 100 * worst, compared);
  ASSERT_GE(compared, 30);
  EXPECT_LT(worst, 0.05);
}
#endif  // STENTSIM_S2S_VALIDATION

}  // namespace
}  // namespace stentsim::solver
