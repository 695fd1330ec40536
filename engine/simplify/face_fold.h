// The geometric legality test of a moved face, shared by the face-geometry constraint and the
// priority modules that choose among placements: a face must not turn by 90 degrees or more,
// nor lose (almost) all its area. Both make folds that later collapses cannot undo.
#pragma once

#include <algorithm>

#include "simplify/vec_math.h"

namespace parapm {

// n is triangle_normal(a, b, c) (|n| is twice the area); a sliver's height is below ~1e-6 of
// its longest side.
inline bool is_sliver(const Vec3& n, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double longest_sq =
      std::max({dot(sub(b, a), sub(b, a)), dot(sub(c, b), sub(c, b)), dot(sub(a, c), sub(a, c))});
  return dot(n, n) <= 1e-12 * longest_sq * longest_sq;
}

// Face (p0, p1, p2) becomes (q0, q1, q2). A face that is already degenerate (zero-area input)
// has no normal to keep: it never folds, so that it is collapsed away rather than blocking
// every collapse around it.
inline bool face_folds(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& q0,
                       const Vec3& q1, const Vec3& q2) {
  const Vec3 before = triangle_normal(p0, p1, p2);
  const Vec3 after = triangle_normal(q0, q1, q2);
  // (the common case, a face that keeps its side and its area, needs no test of the face before)
  if (!(dot(before, after) <= 0) && !is_sliver(after, q0, q1, q2)) return false;
  return !is_sliver(before, p0, p1, p2);
}

}  // namespace parapm
