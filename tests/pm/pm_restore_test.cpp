// restore_input (copies merged, input order back) and compare_meshes_exact.
#include "pm/pm_restore.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "pm/levels.h"
#include "pm_fixtures.h"
#include "test_support.h"
#include "util/error.h"

namespace parapm {
namespace {

// The input, a bow tie: two triangles that share only vertex I0 (non-manifold), listed in
// this order:
//
//   I5 ---- I4          input vertices: I0 (0.5,1) I1 (0,0) I2 (1,0) I3 (1,1) I4 (1,2) I5 (0,2)
//     \    /            input faces:    0 (I0,I4,I5)  1 (I2,I3,I0)  2 (I1,I2,I0)
//      I0 --- I3
//     /  \   /
//   I1 -- I2
//
// The repair step gave the upper fan a copy of I0. The PM: base vertices 0 (0,0), 1 (1,0),
// 2 (0.5,1), 3 (1,2), 4 (0,2), 5 (0.5,1) = copy of 2; base faces (0,1,2), (5,3,4); one
// boundary split (vs 1, vl 2, no vr) creates 6 at (1,1) with fl = (1,6,2) and no fan.
ProgressiveMesh bow_tie_pm() {
  ProgressiveMesh pm;
  pm.base.positions = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {1, 2, 0}, {0, 2, 0}, {0.5, 1, 0}};
  pm.base.faces = {{0, 1, 2}, {5, 3, 4}};
  pm.base.positions_are_float = true;
  VertexSplit s;
  s.vs = 1;
  s.vl = 2;
  s.vs_before = s.vs_after = {1, 0, 0};
  s.vt_after = {1, 1, 0};
  pm.splits.push_back(s);
  pm.vertex_copies = {{5, 2}};
  pm.info.input_vertices = 6;
  pm.info.input_faces = 3;
  pm.input_vertex_order = {1, 2, 0, 4, 5, 0, 3};
  pm.input_face_order = {2, 0, 1};  // full faces: (0,1,2), (5,3,4), (1,6,2)
  return pm;
}

Mesh bow_tie_input() {
  Mesh m;
  m.positions = {{0.5, 1, 0}, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  m.faces = {{0, 4, 5}, {2, 3, 0}, {1, 2, 0}};
  m.positions_are_float = true;
  return m;
}

TEST(RestoreInput, MergesCopiesAndRestoresTheInputOrder) {
  const ProgressiveMesh pm = bow_tie_pm();
  ASSERT_NO_THROW(validate_pm(pm));
  const Mesh restored = restore_input(pm);
  const MeshDifference d = compare_meshes_exact(restored, bow_tie_input(), true);
  EXPECT_TRUE(d.equal) << d.first_difference;
  EXPECT_EQ(restored.faces, bow_tie_input().faces);
}

TEST(RestoreInput, WithoutOrdersKeepsThePmNumberingMinusCopies) {
  ProgressiveMesh pm = bow_tie_pm();
  pm.input_vertex_order.clear();
  pm.input_face_order.clear();
  const Mesh restored = restore_input(pm);
  EXPECT_EQ(restored.vertex_count(), 6u);  // 7 minus the copy; 6 becomes 5
  EXPECT_EQ(restored.faces, (std::vector<Triangle>{{0, 1, 2}, {2, 3, 4}, {1, 5, 2}}));
  const MeshDifference d = compare_meshes_exact(restored, bow_tie_input(), false);
  EXPECT_TRUE(d.equal) << d.first_difference;
}

TEST(RestoreInput, SkipsInputElementsTheRepairRemoved) {
  // The input had 8 vertices and 5 faces; two of each did not survive the repair. The order
  // stays compact.
  ProgressiveMesh pm = bow_tie_pm();
  pm.info.input_vertices = 8;
  pm.info.input_faces = 5;
  pm.input_vertex_order = {2, 3, 0, 6, 7, 0, 5};
  pm.input_face_order = {4, 0, 2};
  const MeshDifference d = compare_meshes_exact(restore_input(pm), bow_tie_input(), true);
  EXPECT_TRUE(d.equal) << d.first_difference;
}

TEST(RestoreInput, AttributesAndRandomPms) {
  for (const ProgressiveMesh& pm :
       {testing::octahedron_pm(true), testing::random_pm(500, {false, true, false, 31})}) {
    const MeshDifference d =
        compare_meshes_exact(restore_input(pm), level_of_detail(pm, pm.splits.size()), true);
    EXPECT_TRUE(d.equal) << d.first_difference;
  }
}

TEST(RestoreInput, ShuffledOrderIsUndone) {
  // Give a random PM an input order that is a random permutation; restoring must put vertex
  // v of the full mesh at index order[v], face f at face_order[f].
  ProgressiveMesh pm = testing::random_pm(300, {true, true, true, 17});
  const Mesh full = level_of_detail(pm, pm.splits.size());
  std::mt19937 rng(5);
  pm.input_vertex_order.resize(full.vertex_count());
  std::iota(pm.input_vertex_order.begin(), pm.input_vertex_order.end(), 0u);
  std::shuffle(pm.input_vertex_order.begin(), pm.input_vertex_order.end(), rng);
  pm.input_face_order.resize(full.face_count());
  std::iota(pm.input_face_order.begin(), pm.input_face_order.end(), 0u);
  std::shuffle(pm.input_face_order.begin(), pm.input_face_order.end(), rng);
  pm.info.input_vertices = full.vertex_count();
  pm.info.input_faces = full.face_count();
  const Mesh restored = restore_input(pm);
  for (VertexId v = 0; v < full.vertex_count(); ++v)
    ASSERT_EQ(restored.positions[pm.input_vertex_order[v]], full.positions[v]);
  for (FaceId f = 0; f < full.face_count(); ++f) {
    const Triangle& t = full.faces[f];
    const Triangle expected = {pm.input_vertex_order[t[0]], pm.input_vertex_order[t[1]],
                               pm.input_vertex_order[t[2]]};
    ASSERT_EQ(restored.faces[pm.input_face_order[f]], expected);
  }
  EXPECT_TRUE(compare_meshes_exact(restored, full, false).equal);
  EXPECT_FALSE(compare_meshes_exact(restored, full, true).equal);
}

TEST(RestoreInput, RejectsAnInvalidPm) {
  ProgressiveMesh pm = bow_tie_pm();
  pm.vertex_copies = {{5, 3}};
  EXPECT_THROW(restore_input(pm), Error);
}

// ---- compare_meshes_exact ------------------------------------------------------------------

Mesh two_triangles(bool attributes) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  m.faces = {{0, 1, 2}, {1, 3, 2}};
  if (attributes) {
    m.layout.colors = true;
    for (VertexId v = 0; v < 4; ++v) {
      m.wedge_vertex.push_back(v);
      m.wedge_values.insert(m.wedge_values.end(), {float(v) / 4, 0.5f, 0.25f, 1});
    }
    m.face_wedges = {{0, 1, 2}, {1, 3, 2}};
  }
  return m;
}

TEST(CompareMeshesExact, RotatedFacesAreEqual) {
  Mesh a = two_triangles(true), b = two_triangles(true);
  b.faces[1] = {3, 2, 1};
  b.face_wedges[1] = {3, 2, 1};
  EXPECT_TRUE(compare_meshes_exact(a, b, true).equal);
  EXPECT_TRUE(compare_meshes_exact(a, b, false).equal);
}

TEST(CompareMeshesExact, ReversedOrientationDiffers) {
  Mesh a = two_triangles(false), b = two_triangles(false);
  b.faces[1] = {1, 2, 3};
  const MeshDifference same = compare_meshes_exact(a, b, true);
  EXPECT_FALSE(same.equal);
  EXPECT_EQ(same.first_difference, "face 1 is (1, 3, 2) vs (1, 2, 3)");
  EXPECT_FALSE(compare_meshes_exact(a, b, false).equal);
}

TEST(CompareMeshesExact, PositionsAreComparedBitForBit) {
  Mesh a = two_triangles(false), b = two_triangles(false);
  b.positions[0][2] = -0.0;
  const MeshDifference d = compare_meshes_exact(a, b, true);
  EXPECT_FALSE(d.equal);
  EXPECT_NE(d.first_difference.find("vertex 0"), std::string::npos) << d.first_difference;
  EXPECT_FALSE(compare_meshes_exact(a, b, false).equal);
  b.positions[0][2] = std::nextafter(0.0, 1.0);
  EXPECT_FALSE(compare_meshes_exact(a, b, false).equal);
}

TEST(CompareMeshesExact, AttributeValuesPerCorner) {
  Mesh a = two_triangles(true), b = two_triangles(true);
  // Same values, different wedge numbering: equal.
  b.wedge_vertex.push_back(3);
  b.wedge_values.insert(b.wedge_values.end(), {0.75f, 0.5f, 0.25f, 1});
  b.face_wedges[1][1] = 4;
  EXPECT_TRUE(compare_meshes_exact(a, b, true).equal);
  // A different value at one corner: not equal, in both modes.
  b.wedge_values[4 * 4 + 3] = 0.5f;
  const MeshDifference d = compare_meshes_exact(a, b, true);
  EXPECT_FALSE(d.equal);
  EXPECT_EQ(d.first_difference, "face 1, corner at vertex 3: the attribute values differ");
  EXPECT_FALSE(compare_meshes_exact(a, b, false).equal);
}

TEST(CompareMeshesExact, RenumberedMeshesAreEqualOnlyUpToRenumbering) {
  Mesh a = two_triangles(true);
  Mesh b;
  b.layout = a.layout;
  // Vertices reversed, faces swapped and rotated, wedges renumbered.
  for (VertexId v = 0; v < 4; ++v) b.positions.push_back(a.positions[3 - v]);
  // a's faces (0,1,2) and (1,3,2) are b's (3,2,1) and (2,0,1); listed swapped and rotated.
  b.faces = {{2, 0, 1}, {1, 3, 2}};
  b.wedge_values = a.wedge_values;
  b.wedge_vertex = {3, 2, 1, 0};
  b.face_wedges = {{1, 3, 2}, {2, 0, 1}};
  EXPECT_TRUE(compare_meshes_exact(a, b, false).equal)
      << compare_meshes_exact(a, b, false).first_difference;
  EXPECT_FALSE(compare_meshes_exact(a, b, true).equal);
  b.faces[0] = {1, 0, 2};  // flipped
  b.face_wedges[0] = {2, 3, 1};
  EXPECT_FALSE(compare_meshes_exact(a, b, false).equal);
}

TEST(CompareMeshesExact, CountsAndMalformedMeshes) {
  Mesh a = two_triangles(false), b = two_triangles(false);
  b.faces.pop_back();
  EXPECT_EQ(compare_meshes_exact(a, b, true).first_difference, "face counts differ: 2 vs 1");
  b = two_triangles(true);
  EXPECT_EQ(compare_meshes_exact(a, b, false).first_difference, "the attribute layouts differ");
  b = two_triangles(false);
  b.faces[0][0] = 9;
  EXPECT_FALSE(compare_meshes_exact(a, b, true).equal);  // a difference, not a crash
}

}  // namespace
}  // namespace parapm
