#include "solver/contact/normal_projection.hpp"

#include <Eigen/LU>

#include <cmath>

namespace stentsim::solver::contact {
namespace {

struct FaceFields {
  Vec3 x = Vec3::Zero(), n = Vec3::Zero();
  std::array<Vec3, 2> dx{Vec3::Zero(), Vec3::Zero()}, dn{Vec3::Zero(), Vec3::Zero()};
  std::array<Vec3, 3> ddx{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}, ddn{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
};

FaceFields fields(const ContactSurface& s, const SurfaceFace& f, const FaceShape& sh) {
  FaceFields r;
  for (int k = 0; k < f.count; ++k) {
    const Vec3& xk = s.x(f.node[k]);
    const Vec3& nk = s.normal(f.node[k]);
    r.x += sh.n[k] * xk, r.n += sh.n[k] * nk;
    for (int a = 0; a < 2; ++a) r.dx[a] += sh.dn[k][a] * xk, r.dn[a] += sh.dn[k][a] * nk;
    for (int a = 0; a < 3; ++a) r.ddx[a] += sh.ddn[k][a] * xk, r.ddn[a] += sh.ddn[k][a] * nk;
  }
  return r;
}

Mat3 jacobian(const FaceFields& f, double alpha) {
  Mat3 j;
  j.col(0) = f.dx[0] + alpha * f.dn[0];
  j.col(1) = f.dx[1] + alpha * f.dn[1];
  j.col(2) = f.n;
  return j;
}

}  // namespace

NormalProjection project_along_normals(const ContactSurface& s, int face, const Vec3& p, double inside_tolerance) {
  const SurfaceFace& f = s.faces()[static_cast<std::size_t>(face)];
  NormalProjection r;
  auto xi = face_center(f.kind);
  FaceFields ff = fields(s, f, face_shape(f.kind, xi[0], xi[1]));
  double alpha = (p - ff.x).dot(ff.n) / ff.n.squaredNorm();
  // Length scale of the face for the convergence test.
  double h = 0.0;
  for (int k = 1; k < f.count; ++k) h = std::max(h, (s.x(f.node[k]) - s.x(f.node[0])).norm());
  // Round-off of F is ~1e-16 of the coordinates' size, which far from the origin exceeds 1e-13 of a face.
  const double tol = 1e-13 * std::max(h, (p - ff.x).norm()) + 1e-14 * std::max(p.norm(), ff.x.norm());
  for (int it = 0; it < 30; ++it) {
    ff = fields(s, f, face_shape(f.kind, xi[0], xi[1]));
    const Vec3 F = ff.x + alpha * ff.n - p;
    const Mat3 J = jacobian(ff, alpha);
    // Singular when det J is round-off against Hadamard's bound |det J| <= Π |J_k| (a
    // scale-free test; the adjugate inverse of a 3 x 3 costs a fraction of a pivoted LU,
    // and this loop runs for every Gauss point and candidate face of every assembly).
    Mat3 inv;
    double det = 0.0;
    bool nonzero = false;
    J.computeInverseAndDetWithCheck(inv, det, nonzero, 0.0);  // det and cofactors once
    if (!nonzero || !(std::abs(det) > 1e-13 * J.col(0).norm() * J.col(1).norm() * J.col(2).norm())) return r;
    const Vec3 dy = -(inv * F);
    xi[0] += dy[0], xi[1] += dy[1], alpha += dy[2];
    if (!std::isfinite(alpha) || std::abs(xi[0]) > 1e3 || std::abs(xi[1]) > 1e3) return r;
    if (F.norm() <= tol && dy.head<2>().norm() <= 1e-12) {
      ff = fields(s, f, face_shape(f.kind, xi[0], xi[1]));
      r.xi = xi;
      r.alpha = alpha;
      r.distance = alpha * ff.n.norm();
      r.direction = ff.n.normalized();
      r.kind = inside_face(f.kind, xi[0], xi[1], inside_tolerance) ? ProjectionKind::inside : ProjectionKind::outside;
      return r;
    }
  }
  return r;
}

void gap_derivatives(const ContactSurface& s, int face, const NormalProjection& pr, bool second, GapDerivatives& out) {
  const SurfaceFace& f = s.faces()[static_cast<std::size_t>(face)];
  const int nf = f.count, N = 3 + 6 * nf;
  const FaceShape sh = face_shape(f.kind, pr.xi[0], pr.xi[1]);
  const FaceFields ff = fields(s, f, sh);
  const double alpha = pr.alpha, rho = ff.n.norm();
  const Vec3 nh = ff.n / rho;
  const Mat3 P = Mat3::Identity() - nh * nh.transpose();
  const Mat3 J = jacobian(ff, alpha);
  const Eigen::PartialPivLU<Mat3> lu(J);
  const Vec3 d_y(alpha * nh.dot(ff.dn[0]), alpha * nh.dot(ff.dn[1]), rho);
  const Vec3 lambda = -J.transpose().partialPivLu().solve(d_y);  // Eigen 3.4.0 has no solve on lu.transpose()
  auto ix = [&](int k) { return 3 + 3 * k; };
  auto in = [&](int k) { return 3 + 3 * nf + 3 * k; };
  // D_v = L_v = d_v + λᵀ F_v.
  out.grad.setZero(N);
  out.grad.segment<3>(0) = -lambda;
  for (int k = 0; k < nf; ++k) {
    out.grad.segment<3>(ix(k)) = sh.n[k] * lambda;
    out.grad.segment<3>(in(k)) = alpha * sh.n[k] * (nh + lambda);
  }
  if (!second) return;
  // F_v (3 x N) and Y = −J⁻¹ F_v (3 x N).
  Eigen::MatrixXd Fv = Eigen::MatrixXd::Zero(3, N);
  Fv.block<3, 3>(0, 0) = -Mat3::Identity();
  for (int k = 0; k < nf; ++k) {
    Fv.block<3, 3>(0, ix(k)) = sh.n[k] * Mat3::Identity();
    Fv.block<3, 3>(0, in(k)) = alpha * sh.n[k] * Mat3::Identity();
  }
  const Eigen::MatrixXd Y = -lu.solve(Fv);
  // L_yy (3 x 3), y = (ξ1, ξ2, α).
  Mat3 Lyy = Mat3::Zero();
  const int ab[2][2] = {{0, 1}, {1, 2}};  // index into ddx/ddn of (a, b)
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      const int c = ab[a][b];
      Lyy(a, b) = alpha * (nh.dot(ff.ddn[c]) + ff.dn[a].dot(P * ff.dn[b]) / rho) + lambda.dot(ff.ddx[c] + alpha * ff.ddn[c]);
    }
    Lyy(a, 2) = Lyy(2, a) = (nh + lambda).dot(ff.dn[a]);
  }
  // L_yv (3 x N).
  Eigen::MatrixXd Lyv = Eigen::MatrixXd::Zero(3, N);
  for (int k = 0; k < nf; ++k) {
    for (int a = 0; a < 2; ++a) {
      Lyv.block<1, 3>(a, ix(k)) = sh.dn[k][a] * lambda.transpose();
      Lyv.block<1, 3>(a, in(k)) = (alpha * (sh.dn[k][a] * (nh + lambda) + sh.n[k] * P * ff.dn[a] / rho)).transpose();
    }
    Lyv.block<1, 3>(2, in(k)) = (sh.n[k] * (nh + lambda)).transpose();
  }
  // L_vv (N x N): only the (n_k, n_l) blocks.
  out.hess.setZero(N, N);
  for (int k = 0; k < nf; ++k)
    for (int l = 0; l < nf; ++l) out.hess.block<3, 3>(in(k), in(l)) = alpha * sh.n[k] * sh.n[l] / rho * P;
  const Eigen::MatrixXd LyvT_Y = Lyv.transpose() * Y;
  out.hess += LyvT_Y + LyvT_Y.transpose() + Y.transpose() * Lyy * Y;
}

void normal_field_derivatives(const ContactSurface& s, int face, const NormalProjection& pr, bool tangent,
                              NormalFieldDerivatives& out) {
  const SurfaceFace& f = s.faces()[static_cast<std::size_t>(face)];
  const int nf = f.count, N = 3 + 6 * nf;
  const FaceShape sh = face_shape(f.kind, pr.xi[0], pr.xi[1]);
  const FaceFields ff = fields(s, f, sh);
  const double alpha = pr.alpha, rho = ff.n.norm();
  out.normal = ff.n / rho;
  for (int k = 0; k < nf; ++k) out.n[static_cast<std::size_t>(k)] = sh.n[k];
  if (!tangent) return;
  GapDerivatives gd;
  gap_derivatives(s, face, pr, false, gd);
  out.gap_grad = gd.grad;
  const Mat3 P = Mat3::Identity() - out.normal * out.normal.transpose();
  const Eigen::PartialPivLU<Mat3> lu(jacobian(ff, alpha));
  Eigen::MatrixXd Fv = Eigen::MatrixXd::Zero(3, N);
  Fv.block<3, 3>(0, 0) = -Mat3::Identity();
  for (int k = 0; k < nf; ++k) {
    Fv.block<3, 3>(0, 3 + 3 * k) = sh.n[k] * Mat3::Identity();
    Fv.block<3, 3>(0, 3 + 3 * nf + 3 * k) = alpha * sh.n[k] * Mat3::Identity();
  }
  const Eigen::MatrixXd Y = -lu.solve(Fv);
  out.dshape.setZero(nf, N);
  Eigen::MatrixXd dn = Eigen::MatrixXd::Zero(3, N);  // ∂n(ξ)/∂v
  for (int k = 0; k < nf; ++k) {
    out.dshape.row(k) = sh.dn[k][0] * Y.row(0) + sh.dn[k][1] * Y.row(1);
    dn += s.normal(f.node[k]) * out.dshape.row(k);
    dn.block<3, 3>(0, 3 + 3 * nf + 3 * k) += sh.n[k] * Mat3::Identity();
  }
  out.dnormal = P / rho * dn;
}

}  // namespace stentsim::solver::contact
