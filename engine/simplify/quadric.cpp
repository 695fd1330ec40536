#include "simplify/quadric.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace parapm {

Quadric& Quadric::operator*=(double s) {
  a00 *= s, a01 *= s, a02 *= s, a11 *= s, a12 *= s, a22 *= s;
  b0 *= s, b1 *= s, b2 *= s;
  c *= s;
  weight *= s;
  return *this;
}

bool Quadric::minimizer(Vec3& out, double relative_threshold) const {
  // Cofactors of the symmetric A; A p = -b.
  const double c00 = a11 * a22 - a12 * a12;
  const double c01 = a02 * a12 - a01 * a22;
  const double c02 = a01 * a12 - a02 * a11;
  const double det = a00 * c00 + a01 * c01 + a02 * c02;
  const double scale = a00 + a11 + a22;
  // A nearly singular A (flat or cylindrical neighbourhood) has no reliable minimiser: the
  // relative threshold keeps the test independent of the model's units.
  if (!(std::fabs(det) > relative_threshold * scale * scale * scale)) return false;
  const double c11 = a00 * a22 - a02 * a02;
  const double c12 = a01 * a02 - a00 * a12;
  const double c22 = a00 * a11 - a01 * a01;
  const double inv = 1.0 / det;
  out[0] = -(c00 * b0 + c01 * b1 + c02 * b2) * inv;
  out[1] = -(c01 * b0 + c11 * b1 + c12 * b2) * inv;
  out[2] = -(c02 * b0 + c12 * b1 + c22 * b2) * inv;
  return std::isfinite(out[0]) && std::isfinite(out[1]) && std::isfinite(out[2]);
}

double Quadric::least_value(const Vec3& about) const {
  // Q(about + y) = y'Ay + 2g'y + Q(about) with g = A about + b; its least value over y is
  // Q(about) - g'A^+g (A is positive semi-definite: a sum of weighted planes).
  Eigen::Matrix3d a;
  a << a00, a01, a02, a01, a11, a12, a02, a12, a22;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(a);
  const Eigen::Vector3d g =
      a * Eigen::Vector3d(about[0], about[1], about[2]) + Eigen::Vector3d(b0, b1, b2);
  const Eigen::Vector3d& lambda = eigen.eigenvalues();  // ascending
  double saved = 0;
  for (int i = 0; i < 3; ++i) {
    if (!(lambda[i] > 1e-12 * lambda[2])) continue;
    const double along = eigen.eigenvectors().col(i).dot(g);
    saved += along * along / lambda[i];
  }
  const double least = evaluate(about) - saved;
  return std::isfinite(least) ? std::max(0.0, least) : 0.0;
}

}  // namespace parapm
