// The first and second moments of a set of points, which give the sum of their squared
// distances to any plane in O(1): sum (n.(x - q))^2 = count (n.(mean - q))^2 + n^T C n, with
// C the scatter matrix about the mean. The energy metric uses it to cost the points of a
// large star at a placement without projecting each one (energy_priority.cpp).
//
// Moments about the mean, not about the origin: the plane's part n^T C n is small next to C's
// in-plane spread, and raw moments far from the origin would lose it to cancellation.
#pragma once

#include <array>

#include <Eigen/Core>

#include "simplify/vec_math.h"

namespace parapm {

struct PointMoments {
  double count = 0;
  Vec3 mean{};
  std::array<double, 6> scatter{};  // xx, xy, xz, yy, yz, zz about the mean

  // Welford's update, stable however many points are added.
  void add(const Vec3& x) {
    count += 1;
    const Vec3 d = sub(x, mean);
    mean = add_scaled(mean, d, 1.0 / count);
    const Vec3 e = sub(x, mean);
    scatter[0] += d[0] * e[0];
    scatter[1] += d[0] * e[1];
    scatter[2] += d[0] * e[2];
    scatter[3] += d[1] * e[1];
    scatter[4] += d[1] * e[2];
    scatter[5] += d[2] * e[2];
  }

  // The sum of the squared distances of the points to the plane through q with unit normal n.
  double plane_distance_sq(const Vec3& q, const Vec3& n) const {
    const double offset = dot(n, sub(mean, q));
    const double spread = n[0] * n[0] * scatter[0] + 2 * n[0] * n[1] * scatter[1] +
                          2 * n[0] * n[2] * scatter[2] + n[1] * n[1] * scatter[3] +
                          2 * n[1] * n[2] * scatter[4] + n[2] * n[2] * scatter[5];
    return count * offset * offset + (spread > 0 ? spread : 0);
  }

 private:
  static Vec3 add_scaled(const Vec3& a, const Vec3& d, double s) {
    return {a[0] + d[0] * s, a[1] + d[1] * s, a[2] + d[2] * s};
  }
};

// The squared distances of the points to the plane of (v, p1, p2), times |n(v)|^2 (n the
// plane's normal (p1 - v) x (p2 - v)), as a quadratic in v: v^T H v - 2 r.v + k, added
// (scaled by s) to h, r and k. It is quadratic because n(v) is linear in v; dividing by |n(v)|^2
// taken at a fixed v gives one step of iteratively reweighted least squares for the vertex v
// of the faces (v, p1, p2) that minimises the points' plane distances.
void add_plane_quadratic(const PointMoments& m, const Vec3& p1, const Vec3& p2, double s,
                         Eigen::Matrix3d& h, Eigen::Vector3d& r, double& k);

}  // namespace parapm
