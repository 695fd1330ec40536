#include "simplify/point_moments.h"

#include <Eigen/Dense>

namespace parapm {

// With c = p1 x p2 and e = p2 - p1, n(v) = c - v x e, so a point's (x - p1).n(v) is
// x.c - v.(e x (x - p1)): linear in v. Summed over the points about their mean,
//   sum ((x - p1).n(v))^2 = count (k0 - k.v)^2 + (c + S v)^T C (c + S v),
// with k = e x (mean - p1), k0 = mean.c, S the matrix of e x (.), C the scatter matrix.
void add_plane_quadratic(const PointMoments& m, const Vec3& p1, const Vec3& p2, double s,
                         Eigen::Matrix3d& h, Eigen::Vector3d& r, double& constant) {
  const Eigen::Vector3d q1(p1[0], p1[1], p1[2]), q2(p2[0], p2[1], p2[2]);
  const Eigen::Vector3d mean(m.mean[0], m.mean[1], m.mean[2]);
  const Eigen::Vector3d e = q2 - q1, c = q1.cross(q2);
  const Eigen::Vector3d k = e.cross(mean - q1);
  const double k0 = mean.dot(c);
  Eigen::Matrix3d skew;
  skew << 0, -e[2], e[1], e[2], 0, -e[0], -e[1], e[0], 0;
  Eigen::Matrix3d scatter;
  scatter << m.scatter[0], m.scatter[1], m.scatter[2], m.scatter[1], m.scatter[3], m.scatter[4],
      m.scatter[2], m.scatter[4], m.scatter[5];
  const Eigen::Matrix3d st_c = skew.transpose() * scatter;
  h += s * (m.count * k * k.transpose() + st_c * skew);
  r += s * (m.count * k0 * k - st_c * c);
  constant += s * (m.count * k0 * k0 + c.dot(scatter * c));
}

}  // namespace parapm
