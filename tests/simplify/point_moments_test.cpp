// The point moments that cost large stars of the energy metric: plane distances in O(1), and
// the quadratic whose reweighted minimum places the moving vertex.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "simplify/point_moments.h"
#include "simplify/surface_samples.h"

namespace parapm {
namespace {

std::vector<Vec3> random_points(SplitMix64& random, int count, const Vec3& centre, double spread) {
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i)
    points.push_back({centre[0] + spread * (random.uniform() - 0.5),
                      centre[1] + spread * (random.uniform() - 0.5),
                      centre[2] + spread * (random.uniform() - 0.5)});
  return points;
}

double direct_plane_sum(const std::vector<Vec3>& points, const Vec3& q, const Vec3& unit_normal) {
  double sum = 0;
  for (const Vec3& x : points) {
    const double d = dot(unit_normal, sub(x, q));
    sum += d * d;
  }
  return sum;
}

TEST(PointMoments, PlaneDistancesMatchTheDirectSumFarFromTheOrigin) {
  SplitMix64 random(3);
  // Far from the origin and tightly clustered: raw moments would cancel; central ones do not.
  const std::vector<Vec3> points = random_points(random, 200, {1e4, -2e4, 3e4}, 1e-2);
  PointMoments m;
  for (const Vec3& x : points) m.add(x);
  EXPECT_EQ(m.count, 200);
  for (int trial = 0; trial < 20; ++trial) {
    Vec3 n{random.uniform() - 0.5, random.uniform() - 0.5, random.uniform() - 0.5};
    n = scale(n, 1 / length(n));
    const Vec3 q = points[size_t(trial)];
    const double expected = direct_plane_sum(points, q, n);
    // (Raw moments about the origin would be off by about 1e-2 relative here.)
    EXPECT_NEAR(m.plane_distance_sq(q, n), expected, 1e-7 * expected) << trial;
  }
}

TEST(PointMoments, PlaneQuadraticIsTheScaledPlaneEnergyAtEveryVertexPosition) {
  SplitMix64 random(11);
  const std::vector<Vec3> points = random_points(random, 50, {0.3, 0.2, 0.1}, 1.0);
  PointMoments m;
  for (const Vec3& x : points) m.add(x);
  const Vec3 p1{1, 0, 0.2}, p2{0, 1, -0.1};
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  double constant = 0;
  add_plane_quadratic(m, p1, p2, 1.0, h, r, constant);
  // sum ((x - p1).n(v))^2 = v^T H v - 2 r.v + K at every v.
  for (int trial = 0; trial < 10; ++trial) {
    const Vec3 v{random.uniform() * 2 - 1, random.uniform() * 2 - 1, random.uniform() * 2 - 1};
    const Vec3 n = triangle_normal(v, p1, p2);
    const double exact = direct_plane_sum(points, p1, scale(n, 1 / length(n))) * dot(n, n);
    const Eigen::Vector3d ev(v[0], v[1], v[2]);
    EXPECT_NEAR(ev.dot(h * ev) - 2 * r.dot(ev) + constant, exact, 1e-9 * (1 + std::abs(exact)))
        << trial;
  }
}

TEST(PointMoments, ReweightedSolveFindsThePlaneOfCoplanarPoints) {
  // Points on the plane z = 0.5 x; the faces (v, p1, p2) around v fit them exactly when v is
  // on that plane: a few reweighted steps from above it bring v down onto it.
  SplitMix64 random(5);
  const std::vector<std::pair<Vec3, Vec3>> rim = {{{1, 0, 0.5}, {0, 1, 0}},
                                                  {{0, 1, 0}, {-1, 0, -0.5}},
                                                  {{-1, 0, -0.5}, {0, -1, 0}},
                                                  {{0, -1, 0}, {1, 0, 0.5}}};
  std::vector<PointMoments> faces(rim.size());
  for (size_t j = 0; j < rim.size(); ++j)
    for (int i = 0; i < 30; ++i) {
      const double u = random.uniform(), w = random.uniform() * (1 - u);
      const Vec3 x = add(scale(rim[j].first, u), scale(rim[j].second, w));
      faces[j].add(x);  // (v = origin is on the plane: the faces' true apex)
    }
  Vec3 v{0.1, -0.05, 0.4};
  for (int step = 0; step < 6; ++step) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Identity() * 1e-9;
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    for (size_t j = 0; j < rim.size(); ++j) {
      const Vec3 n = triangle_normal(v, rim[j].first, rim[j].second);
      double constant = 0;
      add_plane_quadratic(faces[j], rim[j].first, rim[j].second, 1 / dot(n, n), h, r, constant);
    }
    const Eigen::Vector3d next = h.ldlt().solve(r);
    v = {next[0], next[1], next[2]};
  }
  EXPECT_NEAR(v[2], 0.5 * v[0], 1e-6) << "on the points' plane";
  double energy = 0;
  for (size_t j = 0; j < rim.size(); ++j) {
    const Vec3 n = triangle_normal(v, rim[j].first, rim[j].second);
    energy += faces[j].plane_distance_sq(rim[j].first, scale(n, 1 / length(n)));
  }
  EXPECT_LT(energy, 1e-10);
}

}  // namespace
}  // namespace parapm
