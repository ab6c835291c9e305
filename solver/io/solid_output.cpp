#include "solver/io/solid_output.hpp"

#include <Eigen/Eigenvalues>

namespace stentsim::solver {

std::pair<double, Vec3> max_principal(const Mat3& sigma) {
  Eigen::SelfAdjointEigenSolver<Mat3> es(sigma);
  return {es.eigenvalues()(2), es.eigenvectors().col(2)};
}

MeshData solid_output(const SolidBody& body, const Eigen::VectorXd& u) {
  MeshData m = body.mesh();
  const std::size_t nc = m.num_cells();
  DataArray disp{3, {}};
  disp.values.reserve(3 * m.points.size());
  for (std::size_t i = 0; i < m.points.size(); ++i)
    for (int a = 0; a < 3; ++a) disp.values.push_back(u(body.dof(i, a)));
  m.point_data["Displacement"] = std::move(disp);
  const SolidCellFields f = body.cell_fields(u);
  DataArray stress{6, {}}, strain{6, {}}, p1{1, {}}, dir{3, {}}, vm{1, {}}, mat{1, {}};
  for (std::size_t c = 0; c < nc; ++c) {
    const Mat3& s = f.cauchy[c];
    const Mat3& e = f.strain[c];
    for (const auto& ij : kVoigtPairs) {
      stress.values.push_back(s(ij[0], ij[1]));
      strain.values.push_back(e(ij[0], ij[1]));
    }
    const auto [value, vec] = max_principal(s);
    p1.values.push_back(value);
    for (int a = 0; a < 3; ++a) dir.values.push_back(vec(a));
    vm.values.push_back(von_mises(s));
    mat.values.push_back(body.cell_material()[c]);
  }
  m.cell_data["CauchyStress"] = std::move(stress);
  m.cell_data["GreenLagrangeStrain"] = std::move(strain);
  m.cell_data["MaxPrincipalStress"] = std::move(p1);
  m.cell_data["MaxPrincipalDirection"] = std::move(dir);
  m.cell_data["VonMisesStress"] = std::move(vm);
  m.cell_data["MaterialIndex"] = std::move(mat);
  m.field_text["units"] = "mm, N, MPa, s";
  m.field_text["stress"] = "cell means over quadrature points (volume weighted), Cauchy";
  return m;
}

}  // namespace stentsim::solver
