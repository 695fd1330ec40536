// The shape of a mesh's triangles, for the benchmark report: metro judges how far a level of
// detail is from its input, not how well its triangles are shaped, and slivers (triangles with
// a tiny angle) shade badly, morph badly between levels and make poor meshes for anything
// downstream. Simplifiers trade one for the other: an order by distance alone leaves slivers
// where the surface is flat (docs/decisions/notebook-2026-11.md, "E_spring: the distance's price of
// shape").
#pragma once

#include <cstddef>

#include "mesh/mesh.h"

namespace parapm {

struct TriangleQuality {
  size_t faces = 0;
  double min_angle_median = 0;  // degrees: the median over the faces of each face's least angle
  // Fractions of the faces whose least angle is below 1, 5 and 10 degrees (a zero-area face
  // counts as 0 degrees).
  double below_1 = 0, below_5 = 0, below_10 = 0;
};

TriangleQuality triangle_quality(const Mesh& mesh);

}  // namespace parapm
