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
// round(samples_per_face x live faces of positive area) points drawn with probability proportional
// to face area from a generator seeded by `seed`: the same mesh, rate and seed give the same points
// on every platform (no std:: distributions, whose output is implementation-defined).
std::vector<SurfaceSample> sample_surface(const CollapseMesh& mesh, double samples_per_face,
                                          uint64_t seed);
// The same samples, the faces' areas and the draws computed in `loops`' chunks.
std::vector<SurfaceSample> sample_surface(const CollapseMesh& mesh, double samples_per_face,
                                          uint64_t seed, ChunkedLoops& loops);

// splitmix64 (Steele, Lea, Flood 2014): a tiny generator whose output is fixed by its spec.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  // The generator seeded by `seed` after `skipped` outputs: each output adds a constant to
  // the state, so any output is reached at once.
  static SplitMix64 at(uint64_t seed, uint64_t skipped) {
    return SplitMix64(seed + skipped * kGamma);
  }
  uint64_t next() {
    uint64_t z = (state_ += kGamma);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)

 private:
  static constexpr uint64_t kGamma = 0x9e3779b97f4a7c15ull;
  uint64_t state_;
};

}  // namespace parapm
