#include "solver/contact/direction_projection.hpp"

#include <Eigen/LU>

#include <cmath>

namespace stentsim::solver::contact {
namespace {

struct FacePoint {
  Vec3 x = Vec3::Zero();
  std::array<Vec3, 2> dx{Vec3::Zero(), Vec3::Zero()};
  std::array<Vec3, 3> ddx{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};  // x,11  x,12  x,22
};

FacePoint face_point(const ContactSurface& s, const SurfaceFace& f, const FaceShape& sh) {
  FacePoint r;
  for (int k = 0; k < f.count; ++k) {
    const Vec3& xk = s.x(f.node[k]);
    r.x += sh.n[k] * xk;
    for (int a = 0; a < 2; ++a) r.dx[a] += sh.dn[k][a] * xk;
    for (int a = 0; a < 3; ++a) r.ddx[a] += sh.ddn[k][a] * xk;
  }
  return r;
}

Mat3 jacobian(const FacePoint& fp, const Vec3& d) {
  Mat3 j;
  j.col(0) = fp.dx[0];
  j.col(1) = fp.dx[1];
  j.col(2) = -d;
  return j;
}

}  // namespace

DirectionProjection project_along_direction(const ContactSurface& s, int face, const Vec3& p, const Vec3& d,
                                            double inside_tolerance) {
  const SurfaceFace& f = s.faces()[static_cast<std::size_t>(face)];
  DirectionProjection r;
  auto xi = face_center(f.kind);
  FacePoint fp = face_point(s, f, face_shape(f.kind, xi[0], xi[1]));
  double alpha = (fp.x - p).dot(d) / d.squaredNorm();
  double h = 0.0;
  for (int k = 1; k < f.count; ++k) h = std::max(h, (s.x(f.node[k]) - s.x(f.node[0])).norm());
  // Round-off of F is ~1e-16 of the coordinates' size, which far from the origin exceeds 1e-13 of a face.
  const double tol = 1e-13 * std::max(h, (p - fp.x).norm()) + 1e-14 * std::max(p.norm(), fp.x.norm());
  for (int it = 0; it < 30; ++it) {
    fp = face_point(s, f, face_shape(f.kind, xi[0], xi[1]));
    const Vec3 F = fp.x - p - alpha * d;
    // J⁻¹ by cofactors: J's columns a = x,1, b = x,2, c = −d; rows of J⁻¹ are (b×c, c×a, a×b)/det.
    const Vec3 &a = fp.dx[0], &b = fp.dx[1];
    const Vec3 c = -d;
    const Vec3 bc = b.cross(c), ca = c.cross(a), ab = a.cross(b);
    const double det = a.dot(bc);
    if (!(std::abs(det) > 1e-12 * a.norm() * b.norm() * c.norm())) return r;  // the ray is parallel to the face
    const Vec3 dy = -Vec3(bc.dot(F), ca.dot(F), ab.dot(F)) / det;
    xi[0] += dy[0], xi[1] += dy[1], alpha += dy[2];
    if (!std::isfinite(alpha) || std::abs(xi[0]) > 1e3 || std::abs(xi[1]) > 1e3) return r;
    if (F.norm() <= tol && dy.head<2>().norm() <= 1e-12) {
      fp = face_point(s, f, face_shape(f.kind, xi[0], xi[1]));
      r.xi = xi;
      r.alpha = alpha;
      r.face_normal = fp.dx[0].cross(fp.dx[1]).normalized();
      r.kind = inside_face(f.kind, xi[0], xi[1], inside_tolerance) ? ProjectionKind::inside : ProjectionKind::outside;
      return r;
    }
  }
  return r;
}

void direction_gap_derivatives(const ContactSurface& s, int face, const DirectionProjection& pr, const Vec3& d, bool second,
                               GapDerivatives& out) {
  const SurfaceFace& f = s.faces()[static_cast<std::size_t>(face)];
  const int nf = f.count, N = 6 + 3 * nf;
  const FaceShape sh = face_shape(f.kind, pr.xi[0], pr.xi[1]);
  const FacePoint fp = face_point(s, f, sh);
  const double alpha = pr.alpha;
  const Mat3 J = jacobian(fp, d);
  const Eigen::PartialPivLU<Mat3> lu(J);
  const Vec3 lambda = -J.transpose().partialPivLu().solve(Vec3(Vec3::UnitZ()));
  auto ix = [&](int k) { return 6 + 3 * k; };
  out.grad.setZero(N);
  out.grad.segment<3>(0) = -lambda;
  out.grad.segment<3>(3) = -alpha * lambda;
  for (int k = 0; k < nf; ++k) out.grad.segment<3>(ix(k)) = sh.n[k] * lambda;
  if (!second) return;
  Eigen::MatrixXd Fv = Eigen::MatrixXd::Zero(3, N);
  Fv.block<3, 3>(0, 0) = -Mat3::Identity();
  Fv.block<3, 3>(0, 3) = -alpha * Mat3::Identity();
  for (int k = 0; k < nf; ++k) Fv.block<3, 3>(0, ix(k)) = sh.n[k] * Mat3::Identity();
  const Eigen::MatrixXd Y = -lu.solve(Fv);
  Mat3 Lyy = Mat3::Zero();
  Lyy(0, 0) = lambda.dot(fp.ddx[0]);
  Lyy(0, 1) = Lyy(1, 0) = lambda.dot(fp.ddx[1]);
  Lyy(1, 1) = lambda.dot(fp.ddx[2]);
  Eigen::MatrixXd Lyv = Eigen::MatrixXd::Zero(3, N);
  for (int k = 0; k < nf; ++k)
    for (int a = 0; a < 2; ++a) Lyv.block<1, 3>(a, ix(k)) = sh.dn[k][a] * lambda.transpose();
  Lyv.block<1, 3>(2, 3) = -lambda.transpose();
  const Eigen::MatrixXd LyvT_Y = Lyv.transpose() * Y;
  out.hess = LyvT_Y + LyvT_Y.transpose() + Y.transpose() * Lyy * Y;
}

}  // namespace stentsim::solver::contact
