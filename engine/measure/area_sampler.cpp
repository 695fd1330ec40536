#include "measure/area_sampler.h"

#include <algorithm>
#include <cmath>

#include "simplify/vec_math.h"
#include "util/error.h"

namespace parapm {

Vec3 point_at(const Mesh& mesh, FaceId f, const Barycentric& bary) {
  const Triangle& t = mesh.faces[f];
  Vec3 p{0, 0, 0};
  for (int k = 0; k < 3; ++k) p = add(p, scale(mesh.positions[t[k]], bary[k]));
  return p;
}

double face_area(const Mesh& mesh, FaceId f) {
  const Triangle& t = mesh.faces[f];
  return 0.5 *
         length(triangle_normal(mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]));
}

std::vector<FaceId> faces_with_area(const Mesh& mesh, const std::string& role) {
  std::vector<FaceId> faces;
  faces.reserve(mesh.face_count());
  for (FaceId f = 0; f < mesh.face_count(); ++f)
    if (face_area(mesh, f) > 0) faces.push_back(f);
  if (faces.empty()) throw_invalid(role + ": no face with a positive area");
  return faces;
}

double diagonal_of_faces(const Mesh& mesh, const std::vector<FaceId>& faces) {
  Box box;
  box.min = box.max = mesh.positions[mesh.faces[faces.front()][0]];
  for (FaceId f : faces)
    for (VertexId v : mesh.faces[f])
      for (int a = 0; a < 3; ++a) {
        box.min[a] = std::min(box.min[a], mesh.positions[v][a]);
        box.max[a] = std::max(box.max[a], mesh.positions[v][a]);
      }
  return box.diagonal();
}

AreaSampler::AreaSampler(const Mesh& mesh, std::vector<FaceId> faces, uint64_t seed)
    : faces_(std::move(faces)), random_(seed) {
  cumulative_area_.reserve(faces_.size());
  for (FaceId f : faces_) {
    total_area_ += face_area(mesh, f);
    cumulative_area_.push_back(total_area_);
  }
}

SurfacePoint AreaSampler::next() {
  const double target = random_.uniform() * total_area_;
  // upper_bound: a face is picked with probability (its area) / total; the min() guards the
  // last face against rounding in the running sum.
  const size_t i =
      std::min<size_t>(std::upper_bound(cumulative_area_.begin(), cumulative_area_.end(), target) -
                           cumulative_area_.begin(),
                       faces_.size() - 1);
  const double r1 = std::sqrt(random_.uniform()), r2 = random_.uniform();
  SurfacePoint sample;
  sample.face = faces_[i];
  sample.bary = {1 - r1, r1 * (1 - r2), r1 * r2};
  sample.distance_sq = 0;
  return sample;
}

}  // namespace parapm
