#include "simplify/surface_samples.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "simplify/vec_math.h"
#include "util/fresh_pages.h"

namespace parapm {

AreaIndex::AreaIndex(const std::vector<double>& cumulative) : cumulative_(cumulative) {
  const double total = cumulative.empty() ? 0.0 : cumulative.back();
  if (!std::isfinite(total) || !(total > 0)) return;  // (the whole list is searched)
  const size_t buckets = std::max<size_t>(1, cumulative.size() / kPerBucket);
  edge_.resize(buckets + 1);
  first_.resize(buckets + 1);
  for (size_t b = 0; b < buckets; ++b) edge_[b] = total * (double(b) / double(buckets));
  edge_[buckets] = std::numeric_limits<double>::infinity();
  size_t j = 0;
  for (size_t b = 0; b <= buckets; ++b) {
    while (j < cumulative.size() && cumulative[j] <= edge_[b]) ++j;
    first_[b] = j;
  }
  scale_ = double(buckets) / total;
}

size_t AreaIndex::first_above(double target) const {
  auto search = [&](size_t from, size_t to) {
    return size_t(std::upper_bound(cumulative_.begin() + ptrdiff_t(from),
                                   cumulative_.begin() + ptrdiff_t(to), target) -
                  cumulative_.begin());
  };
  if (edge_.empty() || !(target >= 0)) return search(0, cumulative_.size());
  const size_t buckets = edge_.size() - 1;
  size_t b = std::min(buckets - 1, size_t(std::min(target * scale_, double(buckets))));
  while (b > 0 && target < edge_[b]) --b;
  while (b + 1 < buckets && target >= edge_[b + 1]) ++b;
  return search(first_[b], first_[b + 1]);
}

std::vector<SurfaceSample> sample_surface(const CollapseMesh& mesh, double samples_per_face,
                                          uint64_t seed) {
  ChunkedLoops plain;
  return sample_surface(mesh, samples_per_face, seed, plain);
}

std::vector<SurfaceSample> sample_surface(const CollapseMesh& mesh, double samples_per_face,
                                          uint64_t seed, ChunkedLoops& loops) {
  // Each new block's pages touched in `loops`' chunks before its serial fill (fresh_pages.h).
  std::vector<SurfaceSample> samples;
  const size_t expected =
      mesh.live_vertices() +
      size_t(std::llround(std::max(0.0, samples_per_face) * double(mesh.live_faces())));
  samples.reserve(expected);
  touch_pages(samples.data(), expected * sizeof(SurfaceSample), loops);
  // The vertices' samples: each range of vertices counts its own, then writes them after the
  // ranges before it.
  std::vector<size_t> first(loops.ranges(mesh.vertex_capacity()) + 1, 0);
  auto has_faces = [&](size_t v) { return !mesh.faces_of(VertexId(v)).empty(); };
  loops.run_indexed(mesh.vertex_capacity(), [&](size_t range, size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) first[range + 1] += has_faces(v) ? 1 : 0;
  });
  for (size_t r = 1; r < first.size(); ++r) first[r] += first[r - 1];
  samples.resize(first.back());
  loops.run_indexed(mesh.vertex_capacity(), [&](size_t range, size_t begin, size_t end) {
    size_t out = first[range];
    for (size_t v = begin; v < end; ++v)
      if (has_faces(v))
        samples[out++] = {mesh.position(VertexId(v)), mesh.faces_of(VertexId(v))[0], VertexId(v)};
  });
  if (!(samples_per_face > 0)) return samples;

  std::vector<double> area = filled_touched(mesh.face_capacity(), 0.0, loops);
  loops.run(mesh.face_capacity(), [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      if (!mesh.face_alive(FaceId(f))) continue;
      const Triangle& t = mesh.face(FaceId(f));
      area[f] = 0.5 * length(triangle_normal(mesh.position(t[0]), mesh.position(t[1]),
                                             mesh.position(t[2])));
    }
  });
  std::vector<FaceId> faces;
  std::vector<double> cumulative_area;
  faces.reserve(mesh.face_capacity());
  cumulative_area.reserve(mesh.face_capacity());
  touch_pages(faces.data(), faces.capacity() * sizeof(FaceId), loops);
  touch_pages(cumulative_area.data(), cumulative_area.capacity() * sizeof(double), loops);
  double total = 0;
  for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
    if (!(area[f] > 0)) continue;
    total += area[f];
    faces.push_back(f);
    cumulative_area.push_back(total);
  }
  if (faces.empty()) return samples;
  const AreaIndex index(cumulative_area);
  const auto count = static_cast<size_t>(std::llround(samples_per_face * double(faces.size())));
  const size_t drawn_from = samples.size();
  samples.resize(drawn_from + count);
  // Sample i takes the generator's outputs 3i + 1 ... 3i + 3: a range starts the generator
  // where its first sample's draws begin.
  loops.run(count, [&](size_t begin, size_t end) {
    SplitMix64 random = SplitMix64::at(seed, 3 * uint64_t(begin));
    for (size_t i = begin; i < end; ++i) {
      const double target = random.uniform() * total;
      const size_t k = std::min<size_t>(index.first_above(target), faces.size() - 1);
      // Uniform on the triangle: the square-root warp of two uniforms (Turk 1990).
      const double r1 = std::sqrt(random.uniform()), r2 = random.uniform();
      const double u = 1 - r1, v = r1 * (1 - r2), w = r1 * r2;
      const Triangle& t = mesh.face(faces[k]);
      const Vec3 &a = mesh.position(t[0]), &b = mesh.position(t[1]), &c = mesh.position(t[2]);
      samples[drawn_from + i] = {{u * a[0] + v * b[0] + w * c[0], u * a[1] + v * b[1] + w * c[1],
                                  u * a[2] + v * b[2] + w * c[2]},
                                 faces[k],
                                 kNoId};
    }
  });
  return samples;
}

}  // namespace parapm
