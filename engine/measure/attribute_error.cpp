// Attribute and distance error by sampling (Cignoni, Rocchini, Scopigno 1998, "Metro":
// uniform area sampling of one surface, closest points on the other; Hoppe 96 section 4.2:
// attributes compared at the closest point, interpolated barycentrically from the wedges).
// Points on a triangle: the square-root warp of two uniforms (Turk 1990). Closest points:
// closest_point.h (exact).
#include "measure/attribute_error.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "measure/area_sampler.h"
#include "measure/closest_point.h"
#include "simplify/surface_samples.h"
#include "simplify/vec_math.h"
#include "util/error.h"

namespace parapm {
namespace {

constexpr double kDegreesPerRadian = 180.0 / M_PI;

// ---------------------------------------------------------------------------------------------
// Input checks: the meshes may come straight from a reader, so every id is checked before use.

void check_positions(const Mesh& mesh, const std::string& role) {
  for (VertexId v = 0; v < mesh.vertex_count(); ++v)
    for (double c : mesh.positions[v])
      if (!std::isfinite(c))
        throw_invalid(role + ": vertex " + std::to_string(v) + " has a non-finite coordinate");
  for (FaceId f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.faces[f][k] >= mesh.vertex_count())
        throw_invalid(role + ": face " + std::to_string(f) + " names vertex " +
                      std::to_string(mesh.faces[f][k]) + " but the mesh has " +
                      std::to_string(mesh.vertex_count()) + " vertices");
}

void check_wedges(const Mesh& mesh, const std::string& role) {
  if (!mesh.layout.any()) return;
  const size_t floats = mesh.wedge_count() * size_t(mesh.layout.floats_per_wedge());
  if (mesh.wedge_values.size() != floats)
    throw_invalid(role + ": " + std::to_string(mesh.wedge_values.size()) +
                  " attribute values for " + std::to_string(mesh.wedge_count()) + " wedges of " +
                  std::to_string(mesh.layout.floats_per_wedge()) + " values");
  if (mesh.face_wedges.size() != mesh.face_count())
    throw_invalid(role + ": " + std::to_string(mesh.face_wedges.size()) +
                  " face wedge triples for " + std::to_string(mesh.face_count()) + " faces");
  for (FaceId f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.face_wedges[f][k] >= mesh.wedge_count())
        throw_invalid(role + ": face " + std::to_string(f) + " names wedge " +
                      std::to_string(mesh.face_wedges[f][k]) + " but the mesh has " +
                      std::to_string(mesh.wedge_count()) + " wedges");
  for (size_t i = 0; i < floats; ++i)
    if (!std::isfinite(mesh.wedge_values[i]))
      throw_invalid(role + ": wedge " + std::to_string(i / mesh.layout.floats_per_wedge()) +
                    " has a non-finite attribute value");
}

// ---------------------------------------------------------------------------------------------
// Attributes at a surface point, and the differences.

struct Attributes {
  Vec3 normal{};  // not normalised: the barycentric blend of the wedge normals
  std::array<double, 2> texcoord{};
  Vec3 color{};  // RGB; alpha is not compared
};

// Blends the wedges of the face's corners with the point's barycentric coordinates; channels
// the mesh does not have stay zero.
Attributes attributes_at(const Mesh& mesh, const SurfacePoint& point) {
  Attributes result;
  const AttributeLayout& layout = mesh.layout;
  if (!layout.any()) return result;
  for (int corner = 0; corner < 3; ++corner) {
    const float* values = mesh.wedge(mesh.face_wedges[point.face][corner]);
    const double weight = point.bary[corner];
    for (int i = 0; layout.normals && i < 3; ++i)
      result.normal[i] += weight * values[layout.normal_offset() + i];
    for (int i = 0; layout.texcoords && i < 2; ++i)
      result.texcoord[i] += weight * values[layout.texcoord_offset() + i];
    for (int i = 0; layout.colors && i < 3; ++i)
      result.color[i] += weight * values[layout.color_offset() + i];
  }
  return result;
}

// atan2 of |a x b| and a.b: accurate for small angles, where acos of a dot product near 1 loses
// half its digits (acos(1 - 1e-16) is 1.5e-8 rad, not 0).
double angle_degrees(const Vec3& a, const Vec3& b) {
  return std::atan2(length(cross(a, b)), dot(a, b)) * kDegreesPerRadian;
}

// Root mean square and maximum of a stream of non-negative values.
struct RmsMax {
  void add(double value) {
    sum_sq += value * value;
    max = std::max(max, value);
    ++count;
  }
  double rms() const { return count ? std::sqrt(sum_sq / double(count)) : 0.0; }
  double sum_sq = 0, max = 0;
  uint64_t count = 0;
};

struct ErrorSums {
  RmsMax distance, color, texcoord, normal_degrees;
  uint64_t normal_samples_skipped = 0;
};

void add_differences(const Attributes& reference, const Attributes& approx,
                     const AttributeError& channels, ErrorSums& sums) {
  if (channels.colors) sums.color.add(length(sub(reference.color, approx.color)));
  if (channels.texcoords) {
    const double du = reference.texcoord[0] - approx.texcoord[0];
    const double dv = reference.texcoord[1] - approx.texcoord[1];
    sums.texcoord.add(std::hypot(du, dv));
  }
  if (channels.normals) {
    if (dot(reference.normal, reference.normal) > 0 && dot(approx.normal, approx.normal) > 0)
      sums.normal_degrees.add(angle_degrees(reference.normal, approx.normal));
    else
      ++sums.normal_samples_skipped;
  }
}

void store_figures(const ErrorSums& sums, AttributeError& result) {
  result.distance_rms = sums.distance.rms();
  result.distance_max = sums.distance.max;
  result.color_rms = sums.color.rms();
  result.color_max = sums.color.max;
  result.texcoord_rms = sums.texcoord.rms();
  result.texcoord_max = sums.texcoord.max;
  result.normal_rms_degrees = sums.normal_degrees.rms();
  result.normal_max_degrees = sums.normal_degrees.max;
  result.normal_samples_skipped = sums.normal_samples_skipped;
}

}  // namespace

AttributeError measure_attribute_error(const Mesh& reference, const Mesh& approx,
                                       const AttributeErrorOptions& options) {
  if (options.samples == 0) throw_invalid("attribute error: the sample count must be positive");
  // Check both meshes whole before reading any id.
  check_positions(reference, "reference");
  check_wedges(reference, "reference");
  check_positions(approx, "approximation");
  check_wedges(approx, "approximation");

  std::vector<FaceId> reference_faces = faces_with_area(reference, "reference");
  const std::vector<FaceId> approx_faces = faces_with_area(approx, "approximation");

  AttributeError result;
  result.samples = options.samples;
  result.diagonal = diagonal_of_faces(reference, reference_faces);
  result.colors = reference.layout.colors && approx.layout.colors;
  result.texcoords = reference.layout.texcoords && approx.layout.texcoords;
  result.normals = reference.layout.normals && approx.layout.normals;

  AreaSampler sampler(reference, std::move(reference_faces), options.seed);
  ClosestPointGrid grid(approx, approx_faces);
  ErrorSums sums;
  for (uint64_t i = 0; i < options.samples; ++i) {
    const SurfacePoint sample = sampler.next();
    const SurfacePoint nearest = grid.closest_point(point_at(reference, sample.face, sample.bary));
    sums.distance.add(std::sqrt(nearest.distance_sq));
    add_differences(attributes_at(reference, sample), attributes_at(approx, nearest), result, sums);
  }
  store_figures(sums, result);
  return result;
}

}  // namespace parapm
