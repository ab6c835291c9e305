#pragma once
// Fields of a solid body for ParaView: point "Displacement"; cell means of
// "CauchyStress" (xx, yy, zz, xy, yz, xz), "MaxPrincipalStress" and its unit
// "MaxPrincipalDirection", "VonMisesStress", "GreenLagrangeStrain"
// (xx, yy, zz, xy, yz, xz, tensor components) and "MaterialIndex"; the
// input mesh's own arrays (layer tags) are kept.
#include <Eigen/Core>

#include "common/mesh_data.hpp"
#include "solver/terms/solid_body.hpp"

namespace stentsim::solver {

MeshData solid_output(const SolidBody& body, const Eigen::VectorXd& u);

/// Largest eigenvalue of a symmetric tensor and its unit eigenvector.
std::pair<double, Vec3> max_principal(const Mat3& sigma);

}  // namespace stentsim::solver
