// The geometric distance between two surfaces, as metro measures it (Cignoni et al. 1998):
// points drawn uniformly by area on each, their closest points on the other (exact,
// ClosestPointGrid), both directions; RMS over all the samples and the largest distance
// (Hausdorff), relative to the first mesh's bounding-box diagonal. In the engine so that the
// tests can judge a level of detail without the external judge.
#pragma once

#include <cstdint>

#include "mesh/mesh.h"

namespace parapm {

struct SurfaceDistance {
  double rms = 0;        // relative to `a`'s diagonal, both directions together
  double hausdorff = 0;  // relative, the larger of the two directions
  double diagonal = 0;   // of `a`'s faces, model units
  uint64_t samples = 0;  // per direction
};

// Throws Error(kInvalidInput) when a mesh has no face with area or samples is 0.
SurfaceDistance surface_distance(const Mesh& a, const Mesh& b, uint64_t samples, uint64_t seed = 1);

}  // namespace parapm
