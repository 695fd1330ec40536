// Faces that lie back to back: two faces across an edge whose normals are (nearly) opposite,
// as along the rim of a double-sided sheet (each face and its reverse, as exporters write a
// thin part). Their planes are one, so the edge is the sheet's border, as a boundary edge is
// an open sheet's: the metrics keep it as they keep a boundary.
#pragma once

#include <cmath>

#include "simplify/vec_math.h"

namespace parapm {

// Normals within this many degrees of opposite: back to back.
constexpr double kBackToBackDegrees = 10;

// n1, n2: the two faces' normals, of any length (a zero-area face is back to back with none).
inline bool back_to_back(const Vec3& n1, const Vec3& n2) {
  const double lengths = length(n1) * length(n2);
  return lengths > 0 && dot(n1, n2) < -std::cos(kBackToBackDegrees * M_PI / 180) * lengths;
}

}  // namespace parapm
