// The points E_dist measures (Hoppe 93 section 3, Hoppe 96 section 4.1): every vertex of the
// original mesh, plus optional points drawn uniformly by area, each starting on the face it
// lies on (distance zero).
#pragma once

#include <cstddef>
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

// upper_bound over an ascending list of cumulative areas (the draw of a face by area), narrowed
// first by a table of buckets of equal area: bucket b holds the targets in [edge b, edge b + 1),
// whose answers lie between the answers at its two edges (upper_bound is monotone in the
// target), so a draw searches a few entries, not the whole list (a million draws' cache misses).
// The same index as std::upper_bound over the whole list, for every target. Holds a reference
// to `cumulative`, which must outlive it and not change.
class AreaIndex {
 public:
  explicit AreaIndex(const std::vector<double>& cumulative);
  // The index of the first cumulative area above `target`, or the list's size.
  size_t first_above(double target) const;

 private:
  static constexpr size_t kPerBucket = 16;
  const std::vector<double>& cumulative_;
  std::vector<double> edge_;   // per bucket, its least target; then +infinity
  std::vector<size_t> first_;  // per edge, the first cumulative area above it
  double scale_ = 0;           // buckets per unit of area
};

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
