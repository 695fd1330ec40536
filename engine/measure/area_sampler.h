// What the measures share: points on a mesh's faces, face areas, and uniform sampling by
// area from a seeded splitmix64 stream (the same mesh and seed give the same points on every
// platform: std:: distributions are implementation-defined).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "measure/closest_point.h"
#include "mesh/mesh.h"
#include "simplify/surface_samples.h"

namespace parapm {

using Barycentric = std::array<double, 3>;

Vec3 point_at(const Mesh& mesh, FaceId f, const Barycentric& bary);
double face_area(const Mesh& mesh, FaceId f);

// The faces that hold area (zero-area faces add nothing to sample or to be closest to);
// throws Error(kInvalidInput) "<role>: no face with a positive area" when there is none.
std::vector<FaceId> faces_with_area(const Mesh& mesh, const std::string& role);

// The bounding-box diagonal of the faces' corners (vertices no face uses are not measured).
double diagonal_of_faces(const Mesh& mesh, const std::vector<FaceId>& faces);

class AreaSampler {
 public:
  AreaSampler(const Mesh& mesh, std::vector<FaceId> faces, uint64_t seed);
  SurfacePoint next();  // distance_sq 0

 private:
  std::vector<FaceId> faces_;
  std::vector<double> cumulative_area_;
  double total_area_ = 0;
  SplitMix64 random_;
};

}  // namespace parapm
