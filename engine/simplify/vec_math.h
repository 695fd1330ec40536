// Small vector helpers on Vec3 (std::array<double, 3>) for the simplifier's hot loops.
#pragma once

#include <cmath>

#include "mesh/mesh.h"

namespace parapm {

inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double length(const Vec3& a) { return std::sqrt(dot(a, a)); }
// Twice the area vector of triangle (a, b, c).
inline Vec3 triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  return cross(sub(b, a), sub(c, a));
}

}  // namespace parapm
