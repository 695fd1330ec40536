#include "measure/triangle_quality.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace parapm {
namespace {

// The angle at corner a of triangle (a, b, c), degrees; 0 where an edge has no length.
double angle_at(const Vec3& a, const Vec3& b, const Vec3& c) {
  double uv = 0, uu = 0, vv = 0;
  for (int k = 0; k < 3; ++k) {
    const double u = b[k] - a[k], v = c[k] - a[k];
    uv += u * v, uu += u * u, vv += v * v;
  }
  if (!(uu > 0 && vv > 0)) return 0;
  return std::acos(std::clamp(uv / std::sqrt(uu * vv), -1.0, 1.0)) * 180.0 / M_PI;
}

}  // namespace

TriangleQuality triangle_quality(const Mesh& mesh) {
  TriangleQuality q;
  q.faces = mesh.face_count();
  if (q.faces == 0) return q;
  std::vector<double> least;
  least.reserve(q.faces);
  for (const Triangle& t : mesh.faces) {
    const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
    least.push_back(std::min({angle_at(a, b, c), angle_at(b, c, a), angle_at(c, a, b)}));
  }
  const auto share = [&](double degrees) {
    return double(
               std::count_if(least.begin(), least.end(), [&](double x) { return x < degrees; })) /
           double(q.faces);
  };
  q.below_1 = share(1), q.below_5 = share(5), q.below_10 = share(10);
  std::nth_element(least.begin(), least.begin() + ptrdiff_t(q.faces / 2), least.end());
  q.min_angle_median = least[q.faces / 2];
  return q;
}

}  // namespace parapm
