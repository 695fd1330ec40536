#include "simplify/surface_samples.h"

#include <algorithm>
#include <cmath>

#include "simplify/vec_math.h"

namespace parapm {

std::vector<SurfaceSample> sample_surface(const CollapseMesh& mesh, double samples_per_face,
                                          uint64_t seed) {
  std::vector<SurfaceSample> samples;
  samples.reserve(mesh.live_vertices());
  for (VertexId v = 0; v < mesh.vertex_capacity(); ++v)
    if (!mesh.faces_of(v).empty()) samples.push_back({mesh.position(v), mesh.faces_of(v)[0], v});
  if (!(samples_per_face > 0)) return samples;

  std::vector<FaceId> faces;
  std::vector<double> cumulative_area;
  double total = 0;
  for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
    if (!mesh.face_alive(f)) continue;
    const Triangle& t = mesh.face(f);
    const double area = 0.5 * length(triangle_normal(mesh.position(t[0]), mesh.position(t[1]),
                                                     mesh.position(t[2])));
    if (!(area > 0)) continue;
    total += area;
    faces.push_back(f);
    cumulative_area.push_back(total);
  }
  if (faces.empty()) return samples;
  const auto count = static_cast<size_t>(std::llround(samples_per_face * double(faces.size())));
  SplitMix64 random(seed);
  samples.reserve(samples.size() + count);
  for (size_t i = 0; i < count; ++i) {
    const double target = random.uniform() * total;
    const size_t k =
        std::min<size_t>(std::upper_bound(cumulative_area.begin(), cumulative_area.end(), target) -
                             cumulative_area.begin(),
                         faces.size() - 1);
    // Uniform on the triangle: the square-root warp of two uniforms (Turk 1990).
    const double r1 = std::sqrt(random.uniform()), r2 = random.uniform();
    const double u = 1 - r1, v = r1 * (1 - r2), w = r1 * r2;
    const Triangle& t = mesh.face(faces[k]);
    const Vec3 &a = mesh.position(t[0]), &b = mesh.position(t[1]), &c = mesh.position(t[2]);
    samples.push_back({{u * a[0] + v * b[0] + w * c[0], u * a[1] + v * b[1] + w * c[1],
                        u * a[2] + v * b[2] + w * c[2]},
                       faces[k],
                       kNoId});
  }
  return samples;
}

}  // namespace parapm
