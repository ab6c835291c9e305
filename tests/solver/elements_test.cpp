// Element kernels: tangent vs finite differences for every volume element x
// material (incl. the viscous branch over a step), follower pressure and
// springs on every surface element; patch tests of hex8, tet4, tet10.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/materials/presets.hpp"
#include "solver/terms/follower_pressure.hpp"
#include "solver/terms/robin_springs.hpp"
#include "solver/terms/solid_kernel.hpp"
#include "solver/terms/surface_kernel.hpp"
#include "tests/solver/dense_assembler.hpp"
#include "tests/solver/fd_check.hpp"

namespace stentsim::solver {
namespace {

template <class E>
Eigen::Matrix<double, 3, E::kNodes> reference_nodes() {
  Eigen::Matrix<double, 3, E::kNodes> x;
  if constexpr (std::is_same_v<E, fem::Hex8>) {
    for (int i = 0; i < 8; ++i) x.col(i) = Vec3(E::kNodeXi[i][0], E::kNodeXi[i][1], E::kNodeXi[i][2]);
  } else {
    x.template leftCols<4>() << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
    if constexpr (E::kNodes == 10)
      for (int e = 0; e < 6; ++e) x.col(4 + e) = 0.5 * (x.col(E::kEdges[e][0]) + x.col(E::kEdges[e][1]));
  }
  return x;
}

std::vector<Material> test_materials() {
  std::vector<Material> ms;
  Material nh;
  nh.name = "neo-hooke nu=0.45";
  nh.matrix = CoupledNeoHooke::from_young_poisson(1.0, 0.45);
  ms.push_back(nh);
  for (const auto& p : material_preset_names()) ms.push_back(material_preset(p));
  Material tension = material_preset("adventitia");
  tension.name = "adventitia tension-only";
  for (auto& f : tension.fibers) f.law.tension_only = true;
  ms.push_back(tension);
  return ms;
}

template <class E>
double check_solid_element(std::mt19937& rng) {
  using K = SolidElement<E>;
  std::uniform_real_distribution<double> uni(-1, 1);
  std::normal_distribution<double> nrm;
  double worst = 0.0;
  for (const auto& mat : test_materials()) {
    typename K::NodeMat xr = 0.7 * reference_nodes<E>();
    for (int i = 0; i < xr.size(); ++i) xr(i) += 0.05 * uni(rng);
    typename K::NodeMat du;
    for (int i = 0; i < du.size(); ++i) du(i) = 0.08 * uni(rng);
    std::array<Vec3, kMaxFiberFamilies> dirs;
    for (auto& d : dirs) d = Vec3(nrm(rng), nrm(rng), nrm(rng)).normalized();
    std::array<ViscousHistory, K::kPoints> hist, trial;
    for (auto& h : hist) {
      for (int i = 0; i < 6; ++i) h.q(i) = 0.01 * uni(rng), h.s_inf(i) = 0.01 * uni(rng);
    }
    const double dt = 0.1;
    auto residual = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      typename K::NodeMat xc = xr + Eigen::Map<const typename K::NodeMat>(v.data());
      typename K::Vec r;
      auto res = K::evaluate(xr, xc, mat, dirs.data(), hist.data(), trial.data(), dt, r, nullptr);
      EXPECT_TRUE(res.status.ok) << res.status.why;
      return r;
    };
    Eigen::VectorXd u0 = Eigen::Map<const Eigen::VectorXd>(du.data(), K::kDofs);
    typename K::Vec r;
    typename K::Mat k;
    auto res = K::evaluate(xr, xr + du, mat, dirs.data(), hist.data(), trial.data(), dt, r, &k);
    EXPECT_TRUE(res.status.ok);
    const Eigen::MatrixXd kfd = test::fd_jacobian(residual, u0, 1e-7);
    const double err = test::rel_error(k, kfd);
    EXPECT_LT(err, 1e-6) << E::kName << " x " << mat.name;
    worst = std::max(worst, err);
  }
  return worst;
}

TEST(SolverElements, SolidTangentsMatchFiniteDifferences) {
  std::mt19937 rng(3);
  std::printf("worst FD error hex8 %.2e, tet4 %.2e, tet10 %.2e\n", check_solid_element<fem::Hex8>(rng),
              check_solid_element<fem::Tet4>(rng), check_solid_element<fem::Tet10>(rng));
}

template <class S>
Eigen::Matrix<double, 3, S::kNodes> surface_nodes() {
  Eigen::Matrix<double, 3, S::kNodes> x = Eigen::Matrix<double, 3, S::kNodes>::Zero();
  if constexpr (std::is_same_v<S, fem::Quad4>) {
    x << -1, 1, 1, -1, -1, -1, 1, 1, 0, 0, 0, 0;
  } else {
    x.template leftCols<3>() << 0, 1, 0, 0, 0, 1, 0, 0, 0;
    if constexpr (S::kNodes == 6)
      for (int e = 0; e < 3; ++e) x.col(3 + e) = 0.5 * (x.col(S::kEdges[e][0]) + x.col(S::kEdges[e][1]));
  }
  return x;
}

template <class S>
double check_pressure(std::mt19937& rng) {
  using K = SurfaceElement<S>;
  std::uniform_real_distribution<double> uni(-1, 1);
  typename K::NodeMat x = surface_nodes<S>();
  for (int i = 0; i < x.size(); ++i) x(i) += 0.2 * uni(rng);
  const double p = 0.37;
  auto residual = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    typename K::Vec r;
    K::pressure(Eigen::Map<const typename K::NodeMat>(v.data()), p, r, nullptr);
    return r;
  };
  typename K::Vec r;
  typename K::Mat k;
  K::pressure(x, p, r, &k);
  const double err = test::rel_error(k, test::fd_jacobian(residual, Eigen::Map<const Eigen::VectorXd>(x.data(), K::kDofs), 1e-7));
  EXPECT_LT(err, 1e-6) << S::kName;
  // Flat reference face: the resultant is p A n (n outward by node order).
  const typename K::NodeMat flat = surface_nodes<S>();
  K::pressure(flat, p, r, nullptr);
  Vec3 total = Vec3::Zero();
  for (int i = 0; i < S::kNodes; ++i) total += r.template segment<3>(3 * i);
  const double area = K::area(flat);
  EXPECT_NEAR(total.z(), p * area, 1e-14) << S::kName;
  EXPECT_NEAR(total.head<2>().norm(), 0.0, 1e-14);
  return err;
}

TEST(SolverElements, FollowerPressureTangentsMatchFiniteDifferences) {
  std::mt19937 rng(5);
  std::printf("worst FD error pressure quad4 %.2e, tri3 %.2e, tri6 %.2e\n", check_pressure<fem::Quad4>(rng),
              check_pressure<fem::Tri3>(rng), check_pressure<fem::Tri6>(rng));
}

template <class S>
void check_spring() {
  using K = SurfaceElement<S>;
  const typename K::NodeMat x = surface_nodes<S>();
  typename K::NodeMat u;
  for (int i = 0; i < S::kNodes; ++i) u.col(i) = Vec3(0.1, -0.2, 0.3);  // rigid translation
  typename K::Vec r;
  typename K::Mat k;
  K::spring(x, u, 1000.0, r, k);
  Vec3 total = Vec3::Zero();
  for (int i = 0; i < S::kNodes; ++i) total += r.template segment<3>(3 * i);
  EXPECT_LT((total - 1000.0 * K::area(x) * Vec3(0.1, -0.2, 0.3)).norm(), 1e-10) << S::kName;
  EXPECT_LT((k - k.transpose()).norm(), 1e-12);
}

TEST(SolverElements, SpringsGiveStiffnessTimesAreaTimesDisplacement) {
  check_spring<fem::Quad4>();
  check_spring<fem::Tri3>();
  check_spring<fem::Tri6>();
}

// Patch test: a distorted patch under a homogeneous deformation u = A X is in
// equilibrium: the residual at interior nodes vanishes to round-off, and the
// boundary reactions equal the traction of the homogeneous stress.
MeshData distorted_patch(CellType type) {
  MeshData m = box_hex8(2, 2, 2, 1.0, 1.0, 1.0);
  m.points[13] += Vec3(0.08, -0.05, 0.06);  // the centre node
  if (type == CellType::hexahedron) return m;
  m = hex8_to_tet4(m);
  if (type == CellType::tetra) return m;
  m = tet4_to_tet10(m);
  // move the interior edge nodes too (curved tet10 edges stay isoparametric)
  for (std::size_t i = 27; i < m.points.size(); ++i) {
    const Vec3& p = m.points[i];
    if (p.minCoeff() > 1e-9 && p.maxCoeff() < 1 - 1e-9) m.points[i] += Vec3(0.01, 0.02, -0.015);
  }
  return m;
}

// A tet10 whose mid-edge node 4 (edge 0-1) moves by d along the edge has
// J = 1 + 4 d (L0 - L1): at d = 0.4 it is positive at the four Gauss points
// (at least 1 - 1.789 d = 0.28) and -0.6 at corner 1. Such an element is
// inverted and must fail, naming the corner; at d = 0.2 (J = 0.2 there) it is fine.
TEST(SolverElements, Tet10InvertedAtACornerBetweenPositiveGaussPointsFails) {
  using K = SolidElement<fem::Tet10>;
  Material nh;
  nh.name = "nh";
  nh.matrix = CoupledNeoHooke::from_young_poisson(1.0, 0.45);
  const K::NodeMat xr = reference_nodes<fem::Tet10>();
  std::array<Vec3, kMaxFiberFamilies> dirs{};
  auto evaluate = [&](double d) {
    K::NodeMat xc = xr;
    xc(0, 4) += d;
    K::Vec r;
    K::Mat k;
    return K::evaluate(xr, xc, nh, dirs.data(), nullptr, nullptr, 1.0, r, &k);
  };
  const auto bad = evaluate(0.4);
  EXPECT_FALSE(bad.status.ok);
  EXPECT_EQ(bad.corner, 1);
  EXPECT_EQ(bad.point, -1);
  EXPECT_NE(std::string(bad.status.why).find("inverted"), std::string::npos);
  const auto fine = evaluate(0.2);
  EXPECT_TRUE(fine.status.ok) << fine.status.why;
  EXPECT_EQ(K::inverted_corner(xr, xr), -1);
}

TEST(SolverElements, PatchTests) {
  for (CellType type : {CellType::hexahedron, CellType::tetra, CellType::quadratic_tetra}) {
    SolidBodySpec spec;
    spec.name = "patch";
    spec.mesh = distorted_patch(type);
    Material m = material_preset("adventitia");
    for (auto& f : m.fibers) f.global_direction = Vec3(1, 2, 3);
    spec.materials = {m};
    spec.cell_material.assign(spec.mesh.num_cells(), 0);
    SolidBody body(spec, 0);
    Mat3 a;
    a << 0.1, 0.05, -0.02, 0.03, -0.08, 0.04, 0.0, 0.06, 0.12;
    Eigen::VectorXd u(body.num_dofs());
    for (std::size_t i = 0; i < body.num_nodes(); ++i) u.segment<3>(3 * static_cast<Eigen::Index>(i)) = a * body.mesh().points[i];
    test::DenseAssembler out(body.num_dofs());
    body.assemble(SystemState{u, 1.0, 0.1}, out);
    double interior = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < body.num_nodes(); ++i) {
      const Vec3& p = body.mesh().points[i];
      const double ri = out.r.segment<3>(3 * static_cast<Eigen::Index>(i)).norm();
      scale = std::max(scale, ri);
      if (p.minCoeff() > 1e-9 && p.maxCoeff() < 1 - 1e-9) interior = std::max(interior, ri);
    }
    std::printf("patch %d: max interior residual %.2e (boundary scale %.2e)\n", static_cast<int>(type), interior, scale);
    EXPECT_LT(interior, 1e-13 * scale) << static_cast<int>(type);
    // Every node's residual equals the consistent nodal force of the homogeneous
    // first Piola-Kirchhoff traction P N on the boundary faces: f_I = int N_I dA P N.
    const Mat3 f = Mat3::Identity() + a;
    Vec6 s;
    const auto dirs = body.fiber_directions(0);
    ASSERT_TRUE(m.elastic(f.transpose() * f, dirs.data(), s, nullptr).ok);
    const Mat3 p1 = f * from_voigt_stress(s);
    Eigen::VectorXd expected = Eigen::VectorXd::Zero(body.num_dofs());
    for (const auto& face : fem::boundary_faces(body.mesh())) {
      const Vec3 x0 = body.mesh().points[static_cast<std::size_t>(face.nodes[0])];
      const Vec3 n = (body.mesh().points[static_cast<std::size_t>(face.nodes[1])] - x0)
                         .cross(body.mesh().points[static_cast<std::size_t>(face.nodes[2])] - x0).normalized();
      auto add = [&]<class S>() {
        using K = SurfaceElement<S>;
        typename K::NodeMat xr, t;
        for (int i = 0; i < S::kNodes; ++i) xr.col(i) = body.mesh().points[static_cast<std::size_t>(face.nodes[i])], t.col(i) = p1 * n;
        typename K::Vec r;
        typename K::Mat k;
        K::spring(xr, t, 1.0, r, k);  // = int N_I N_J dA (P N) = int N_I dA (P N)
        for (int i = 0; i < S::kNodes; ++i) expected.segment<3>(3 * face.nodes[i]) += r.template segment<3>(3 * i);
      };
      if (face.type == CellType::quad) add.template operator()<fem::Quad4>();
      else if (face.type == CellType::triangle) add.template operator()<fem::Tri3>();
      else add.template operator()<fem::Tri6>();
    }
    const double err = (out.r - expected).norm() / expected.norm();
    std::printf("patch %d: nodal forces vs boundary traction %.2e\n", static_cast<int>(type), err);
    EXPECT_LT(err, 1e-13);
  }
}

}  // namespace
}  // namespace stentsim::solver
