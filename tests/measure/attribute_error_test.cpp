// measure_attribute_error and its closest-point grid: exact answers on drawn meshes (a
// square of two triangles, moved or recoloured), zero on real meshes against themselves,
// determinism, channels, input errors, and the grid against brute force.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "drawn_meshes.h"
#include "io/mesh_io.h"
#include "measure/attribute_error.h"
#include "measure/closest_point.h"
#include "mesh/repair.h"
#include "simplify/point_projection.h"
#include "simplify/surface_samples.h"
#include "test_support.h"
#include "util/error.h"

namespace parapm {
namespace {

//  3 ---- 2      the unit square in z = 0, two triangles {0, 1, 2} and {0, 2, 3};
//  |  /   |      vertex 1 is in the first only, vertex 3 in the second only.
//  | /    |      colours (RGBA, one wedge per vertex): 0 black, 1 red, 2 green, 3 blue.
//  0 ---- 1
Mesh coloured_square() {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.faces = {{0, 1, 2}, {0, 2, 3}};
  m.layout.colors = true;
  m.wedge_vertex = {0, 1, 2, 3};
  m.wedge_values = {0, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1};
  m.face_wedges = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

Mesh translated(Mesh m, const Vec3& offset) {
  for (Vec3& p : m.positions)
    for (int a = 0; a < 3; ++a) p[a] += offset[a];
  return m;
}

Mesh without_attributes(Mesh m) {
  m.layout = {};
  m.wedge_vertex.clear();
  m.wedge_values.clear();
  m.face_wedges.clear();
  return m;
}

Mesh read_repaired(const std::string& name) {
  return repair_mesh(read_mesh(testing::test_data(name))).mesh;
}

AttributeErrorOptions samples(uint64_t count, uint64_t seed = 1) {
  AttributeErrorOptions options;
  options.samples = count;
  options.seed = seed;
  return options;
}

template <class F>
void expect_invalid_input(F&& f) {
  try {
    f();
    ADD_FAILURE() << "did not throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput) << e.what();
  }
}

TEST(AttributeError, TheSquareAgainstItselfIsZero) {
  const Mesh square = coloured_square();
  const AttributeError e = measure_attribute_error(square, square, samples(10000));
  EXPECT_EQ(e.samples, 10000u);
  EXPECT_NEAR(e.diagonal, std::sqrt(2.0), 1e-15);
  EXPECT_TRUE(e.colors);
  EXPECT_FALSE(e.texcoords);
  EXPECT_FALSE(e.normals);
  EXPECT_LT(e.distance_max, 1e-15);
  EXPECT_LT(e.color_max, 1e-12);
}

// Moved along its normal, every point of the square is exactly `offset` away, above the same
// barycentric point: same colour.
TEST(AttributeError, ATranslatedCopyIsTheOffsetAwayWithTheSameColours) {
  const Mesh square = coloured_square();
  const Mesh lifted = translated(square, {0, 0, 0.25});
  const AttributeError e = measure_attribute_error(square, lifted, samples(20000));
  EXPECT_NEAR(e.distance_rms, 0.25, 1e-12);
  EXPECT_NEAR(e.distance_max, 0.25, 1e-12);
  EXPECT_LT(e.color_max, 1e-12);
  // Sideways by 0.5, a point of the strip x < 0.5 is 0.5 - x from the copy's edge, the others
  // are on the copy: the mean square is the integral of (0.5 - x)^2 over [0, 0.5], 1/24.
  const AttributeError sideways =
      measure_attribute_error(square, translated(square, {0.5, 0, 0}), samples(20000));
  EXPECT_NEAR(sideways.distance_max, 0.5, 1e-3);
  EXPECT_LE(sideways.distance_max, 0.5);
  EXPECT_NEAR(sideways.distance_rms, std::sqrt(1.0 / 24.0), 0.003);
}

// Vertex 1's red goes from 1 to 0.4: the colour difference at a point of face {0, 1, 2} is
// 0.6 x its barycentric weight w of vertex 1, and 0 on the other face. Uniformly on a
// triangle E[w^2] = 1/6 (Dirichlet(1, 1, 1)), half the area is affected, so the RMS is
// 0.6 sqrt(1/12); the maximum is at most the change (reached at the vertex).
TEST(AttributeError, ChangingOneVertexColourGivesItsInterpolatedShare) {
  const Mesh square = coloured_square();
  Mesh recoloured = square;
  recoloured.wedge_values[4] = 0.4f;
  const AttributeError e = measure_attribute_error(square, recoloured, samples(200000));
  EXPECT_LT(e.distance_max, 1e-15);
  EXPECT_GT(e.color_rms, 0);
  EXPECT_LE(e.color_max, 0.6 + 1e-6);
  EXPECT_GT(e.color_max, 0.55);
  EXPECT_NEAR(e.color_rms, 0.6 * std::sqrt(1.0 / 12.0), 0.003);
}

TEST(AttributeError, AlphaIsNotCompared) {
  const Mesh square = coloured_square();
  Mesh transparent = square;
  for (size_t w = 0; w < 4; ++w) transparent.wedge_values[w * 4 + 3] = 0;
  EXPECT_LT(measure_attribute_error(square, transparent, samples(1000)).color_max, 1e-12);
}

TEST(AttributeError, TheSameSeedGivesTheSameFigures) {
  const Mesh square = coloured_square();
  Mesh recoloured = square;
  recoloured.wedge_values[4] = 0.4f;
  const AttributeError a = measure_attribute_error(square, recoloured, samples(5000, 7));
  const AttributeError b = measure_attribute_error(square, recoloured, samples(5000, 7));
  const AttributeError c = measure_attribute_error(square, recoloured, samples(5000, 8));
  EXPECT_EQ(a.color_rms, b.color_rms);
  EXPECT_EQ(a.color_max, b.color_max);
  EXPECT_EQ(a.distance_rms, b.distance_rms);
  EXPECT_NE(a.color_rms, c.color_rms);
}

TEST(AttributeError, ChannelsCountOnlyWhenBothMeshesHaveThem) {
  const Mesh square = coloured_square();
  const Mesh plain = without_attributes(square);
  for (const auto& [reference, approx] :
       {std::pair{&plain, &plain}, std::pair{&square, &plain}, std::pair{&plain, &square}}) {
    const AttributeError e =
        measure_attribute_error(*reference, translated(*approx, {0, 0, 1}), samples(1000));
    EXPECT_FALSE(e.colors);
    EXPECT_FALSE(e.texcoords);
    EXPECT_FALSE(e.normals);
    EXPECT_EQ(e.color_rms, 0);
    EXPECT_NEAR(e.distance_rms, 1, 1e-12);  // distances are measured all the same
  }
}

// Wedge normals: the square's corners tilted by known angles about the x axis.
TEST(AttributeError, NormalsAreComparedByAngle) {
  Mesh square = without_attributes(coloured_square());
  square.layout.normals = true;
  square.wedge_vertex = {0, 1, 2, 3};
  square.face_wedges = {{0, 1, 2}, {0, 2, 3}};
  square.wedge_values.clear();
  for (int v = 0; v < 4; ++v) square.wedge_values.insert(square.wedge_values.end(), {0, 0, 1});
  Mesh tilted = square;
  const double angle = 10 * M_PI / 180;
  for (int v = 0; v < 4; ++v) {
    tilted.wedge_values[v * 3 + 1] = float(std::sin(angle));
    tilted.wedge_values[v * 3 + 2] = float(std::cos(angle));
  }
  const AttributeError e = measure_attribute_error(square, tilted, samples(1000));
  EXPECT_TRUE(e.normals);
  EXPECT_NEAR(e.normal_rms_degrees, 10, 1e-5);
  EXPECT_NEAR(e.normal_max_degrees, 10, 1e-5);
  EXPECT_EQ(e.normal_samples_skipped, 0u);
}

TEST(AttributeError, ZeroAreaFacesAreSkipped) {
  Mesh square = coloured_square();
  square.faces.push_back({0, 1, 1});  // repeated corner
  square.face_wedges.push_back({0, 1, 1});
  const AttributeError e = measure_attribute_error(square, square, samples(1000));
  EXPECT_LT(e.distance_max, 1e-15);
}

TEST(AttributeError, BadInputIsAnInvalidInputError) {
  const Mesh square = coloured_square();
  expect_invalid_input([&] { measure_attribute_error(Mesh{}, square); });
  expect_invalid_input([&] { measure_attribute_error(square, Mesh{}); });
  expect_invalid_input([&] { measure_attribute_error(square, square, samples(0)); });
  Mesh flat = square;
  flat.positions[2] = {0.5, 0.5, 0};  // both faces collinear: no area left
  flat.positions[3] = {0.25, 0.25, 0};
  flat.positions[1] = {0.75, 0.75, 0};
  expect_invalid_input([&] { measure_attribute_error(flat, square); });
  Mesh out_of_range = square;
  out_of_range.faces[1][2] = 9;
  expect_invalid_input([&] { measure_attribute_error(square, out_of_range); });
  Mesh bad_wedge = square;
  bad_wedge.face_wedges[0][1] = 9;
  expect_invalid_input([&] { measure_attribute_error(bad_wedge, square); });
  Mesh short_values = square;
  short_values.wedge_values.pop_back();
  expect_invalid_input([&] { measure_attribute_error(square, short_values); });
  Mesh not_finite = square;
  not_finite.positions[0][1] = std::numeric_limits<double>::quiet_NaN();
  expect_invalid_input([&] { measure_attribute_error(not_finite, square); });
}

TEST(AttributeError, TheColouredAirplaneAgainstItselfIsZero) {
  const Mesh airplane = read_repaired("pymeshlab-colored-airplane-11k.ply");
  ASSERT_TRUE(airplane.layout.colors);
  const AttributeError e = measure_attribute_error(airplane, airplane, samples(50000));
  EXPECT_TRUE(e.colors);
  EXPECT_GT(e.diagonal, 0);
  EXPECT_LT(e.distance_max, 1e-9 * e.diagonal);
  EXPECT_LT(e.color_rms, 1e-6);
  EXPECT_LT(e.color_max, 1e-5);
}

TEST(AttributeError, TheTexturedBunnyAgainstItselfIsZero) {
  const Mesh bunny = read_repaired("pymeshlab-bunny-textured-10k.obj");
  ASSERT_TRUE(bunny.layout.texcoords);
  const AttributeError e = measure_attribute_error(bunny, bunny, samples(50000));
  EXPECT_TRUE(e.texcoords);
  EXPECT_LT(e.distance_max, 1e-9 * e.diagonal);
  EXPECT_LT(e.texcoord_rms, 1e-6);
  EXPECT_LT(e.texcoord_max, 1e-5);
}

// Every colour set to mid-grey: a real difference, positive and at most the distance from
// grey to a corner of the colour cube.
TEST(AttributeError, ARecolouredAirplaneShowsItsChange) {
  const Mesh airplane = read_repaired("pymeshlab-colored-airplane-11k.ply");
  Mesh grey = airplane;
  const int floats = grey.layout.floats_per_wedge();
  const int offset = grey.layout.color_offset();
  for (size_t w = 0; w < grey.wedge_count(); ++w)
    for (int i = 0; i < 3; ++i) grey.wedge_values[w * floats + offset + i] = 0.5f;
  const AttributeError e = measure_attribute_error(airplane, grey, samples(20000));
  EXPECT_GT(e.color_rms, 0.01);
  EXPECT_LE(e.color_max, std::sqrt(3.0) * 0.5 + 1e-6);
}

// The grid's answer is the brute-force minimum over all faces, bit for bit (same projection
// function), for points on, near, inside and far outside a rippled sphere.
TEST(ClosestPointGrid, MatchesBruteForce) {
  const Mesh sphere = testing::uv_sphere(24, 48, 0.3);
  std::vector<FaceId> faces(sphere.face_count());
  for (FaceId f = 0; f < faces.size(); ++f) faces[f] = f;
  ClosestPointGrid grid(sphere, faces);
  SplitMix64 random(3);
  for (int i = 0; i < 3000; ++i) {
    const double reach = i < 1000 ? 1.5 : i < 2000 ? 4 : 100;
    const Vec3 p{(2 * random.uniform() - 1) * reach, (2 * random.uniform() - 1) * reach,
                 (2 * random.uniform() - 1) * reach};
    double brute = std::numeric_limits<double>::infinity();
    for (const Triangle& t : sphere.faces)
      brute = std::min(brute, project_on_triangle(p, sphere.positions[t[0]], sphere.positions[t[1]],
                                                  sphere.positions[t[2]])
                                  .distance_sq);
    const SurfacePoint found = grid.closest_point(p);
    ASSERT_EQ(found.distance_sq, brute) << "query " << i;
  }
}

// A flat mesh has a grid one cell thick; queries above and below it are clamped into it.
TEST(ClosestPointGrid, AFlatMeshAnsweredFromAboveAndBelow) {
  const Mesh square = coloured_square();
  ClosestPointGrid grid(square, {0, 1});
  EXPECT_DOUBLE_EQ(grid.closest_point({0.7, 0.2, 3}).distance_sq, 9);
  EXPECT_DOUBLE_EQ(grid.closest_point({0.2, 0.7, -2}).distance_sq, 4);
  const SurfacePoint corner = grid.closest_point({2, 2, 0});
  EXPECT_DOUBLE_EQ(corner.distance_sq, 2);
  EXPECT_NE(corner.face, kNoId);
}

}  // namespace
}  // namespace parapm
