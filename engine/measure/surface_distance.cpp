#include "measure/surface_distance.h"

#include <algorithm>
#include <cmath>

#include "measure/area_sampler.h"
#include "measure/closest_point.h"
#include "util/error.h"

namespace parapm {
namespace {

struct OneWay {
  double sum_sq = 0;
  double max_sq = 0;
};

// Samples on `from`, distances to `to`.
OneWay one_way(const Mesh& from, const std::vector<FaceId>& from_faces, const Mesh& to,
               const std::vector<FaceId>& to_faces, uint64_t samples, uint64_t seed) {
  ClosestPointGrid grid(to, to_faces);
  AreaSampler sampler(from, from_faces, seed);
  OneWay out;
  for (uint64_t i = 0; i < samples; ++i) {
    const SurfacePoint s = sampler.next();
    const double d = grid.closest_point(point_at(from, s.face, s.bary)).distance_sq;
    out.sum_sq += d;
    out.max_sq = std::max(out.max_sq, d);
  }
  return out;
}

}  // namespace

SurfaceDistance surface_distance(const Mesh& a, const Mesh& b, uint64_t samples, uint64_t seed) {
  if (samples == 0) throw_invalid("surface distance: the sample count must be positive");
  const std::vector<FaceId> a_faces = faces_with_area(a, "first mesh");
  const std::vector<FaceId> b_faces = faces_with_area(b, "second mesh");
  SurfaceDistance out;
  out.samples = samples;
  out.diagonal = diagonal_of_faces(a, a_faces);
  const OneWay forward = one_way(a, a_faces, b, b_faces, samples, seed);
  const OneWay backward = one_way(b, b_faces, a, a_faces, samples, seed + 1);
  const double scale = out.diagonal > 0 ? 1 / out.diagonal : 0;
  out.rms = std::sqrt((forward.sum_sq + backward.sum_sq) / double(2 * samples)) * scale;
  out.hausdorff = std::sqrt(std::max(forward.max_sq, backward.max_sq)) * scale;
  return out;
}

}  // namespace parapm
