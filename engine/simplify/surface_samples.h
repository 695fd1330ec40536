// The points E_dist measures (Hoppe 93 section 3, Hoppe 96 section 4.1): every vertex of the
// original mesh, plus optional points drawn uniformly by area, each starting on the face it
// lies on (distance zero).
#pragma once

#include <cstdint>
#include <vector>

#include "simplify/collapse_mesh.h"

namespace parapm {

struct SurfaceSample {
  Vec3 position{};
  FaceId face = kNoId;
  VertexId vertex = kNoId;  // the vertex it is the sample of, or kNoId for an area sample
};

// Every vertex that has a face (on the first face of its list), then
// round(samples_per_face x live faces) points drawn with probability proportional to face area
// from a generator seeded by `seed`: the same mesh, rate and seed give the same points on every
// platform (no std:: distributions, whose output is implementation-defined).
std::vector<SurfaceSample> sample_surface(const CollapseMesh& mesh, double samples_per_face,
                                          uint64_t seed);

// splitmix64 (Steele, Lea, Flood 2014): a tiny generator whose output is fixed by its spec.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)

 private:
  uint64_t state_;
};

}  // namespace parapm
