// surface_distance: exact answers where they are known (a mesh against itself, against a
// parallel copy), symmetry of the Hausdorff part, and a real mesh against a coarser level.
#include <gtest/gtest.h>

#include <cmath>

#include "io/mesh_io.h"
#include "measure/surface_distance.h"
#include "test_support.h"
#include "util/error.h"

namespace parapm {
namespace {

// A unit square in the plane z = `z`, two triangles.
Mesh square(double z) {
  Mesh m;
  m.positions = {{0, 0, z}, {1, 0, z}, {1, 1, z}, {0, 1, z}};
  m.faces = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TEST(SurfaceDistance, AMeshIsAtDistanceZeroFromItself) {
  const Mesh mesh = read_mesh(testing::test_data("stratocaster-9k.ply"));
  const SurfaceDistance d = surface_distance(mesh, mesh, 5000);
  // Zero up to rounding (a sample is a barycentric combination, then projected back; thin
  // triangles amplify the last bits): far below any simplification's 1e-5 and up.
  EXPECT_LT(d.rms, 1e-9);
  EXPECT_LT(d.hausdorff, 1e-8);
  EXPECT_GT(d.diagonal, 0);
}

TEST(SurfaceDistance, ParallelPlanesAreTheirGapApart) {
  const SurfaceDistance d = surface_distance(square(0), square(0.25), 2000);
  EXPECT_NEAR(d.diagonal, std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(d.rms * d.diagonal, 0.25, 1e-12);
  EXPECT_NEAR(d.hausdorff * d.diagonal, 0.25, 1e-12);
}

TEST(SurfaceDistance, HausdorffSeesWhatOnlyOneSideHas) {
  // The second mesh is the square plus a far triangle: distances from the square to it are
  // zero, the far triangle's to the square are not; the Hausdorff part takes the larger side.
  Mesh with_extra = square(0);
  with_extra.positions.push_back({0, 0, 2});
  with_extra.positions.push_back({1, 0, 2});
  with_extra.positions.push_back({0, 1, 2});
  with_extra.faces.push_back({4, 5, 6});
  const SurfaceDistance d = surface_distance(square(0), with_extra, 4000);
  EXPECT_NEAR(d.hausdorff * d.diagonal, 2.0, 1e-9);
  EXPECT_GT(d.rms, 0);
}

TEST(SurfaceDistance, BadArgumentsAreErrors) {
  const Mesh empty;
  EXPECT_THROW(surface_distance(square(0), square(1), 0), Error);
  EXPECT_THROW(surface_distance(empty, square(1), 10), Error);
}

}  // namespace
}  // namespace parapm
