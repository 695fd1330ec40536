// Triangle shape for the benchmark report (measure/triangle_quality.h).
#include <gtest/gtest.h>

#include <cmath>

#include "io/mesh_io.h"
#include "measure/triangle_quality.h"
#include "test_support.h"

namespace parapm {
namespace {

// Three drawn triangles: equilateral (60 degrees), a right isosceles one (45) and a sliver
// whose least angle is 3 degrees; one zero-area face, whose least angle counts as 0.
TEST(TriangleQuality, DrawnTrianglesHaveTheirLeastAngles) {
  Mesh mesh;
  const double h = std::sqrt(3.0) / 2;
  const double sliver = std::tan(3.0 * M_PI / 180.0);  // apex over the middle of a unit edge
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0.5, h, 0},
                    {0, 0, 1}, {1, 0, 1}, {0, 1, 1},
                    {0, 0, 2}, {1, 0, 2}, {0.5, 0.5 * sliver, 2},
                    {0, 0, 3}, {1, 0, 3}, {2, 0, 3}};
  mesh.faces = {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}};
  TriangleQuality q = triangle_quality(mesh);
  EXPECT_EQ(q.faces, 3u);
  EXPECT_NEAR(q.min_angle_median, 45.0, 1e-9);
  EXPECT_DOUBLE_EQ(q.below_1, 0.0);
  EXPECT_DOUBLE_EQ(q.below_5, 1.0 / 3);
  EXPECT_DOUBLE_EQ(q.below_10, 1.0 / 3);
  mesh.faces.push_back({9, 10, 11});  // collinear
  q = triangle_quality(mesh);
  EXPECT_DOUBLE_EQ(q.below_1, 0.25);
  EXPECT_DOUBLE_EQ(q.below_5, 0.5);
  EXPECT_TRUE(triangle_quality(Mesh{}).faces == 0);
}

// A real scan: nearly every triangle is well shaped, and the fractions nest.
TEST(TriangleQuality, ARealScanIsMostlyWellShaped) {
  const TriangleQuality q =
      triangle_quality(read_mesh(testing::test_data("pymeshlab-bunny-textured-10k.obj")));
  EXPECT_EQ(q.faces, 9999u);
  EXPECT_GT(q.min_angle_median, 25.0);
  EXPECT_LE(q.below_1, q.below_5);
  EXPECT_LE(q.below_5, q.below_10);
  EXPECT_LT(q.below_10, 0.1);
}

}  // namespace
}  // namespace parapm
