// PM operations on a PM built from a real mesh (the hand-drawn cases are in tests/pm):
// geomorph endpoints, selective refinement, undo.
#include <gtest/gtest.h>

#include <algorithm>

#include "io/mesh_io.h"
#include "pm/geomorph.h"
#include "pm/levels.h"
#include "pm/mesh_compare.h"
#include "pm/pm_cursor.h"
#include "pm/selective_refinement.h"
#include "simplify/simplify.h"
#include "test_support.h"

namespace parapm {
namespace {

const ProgressiveMesh& airplane_pm() {
  static const ProgressiveMesh pm = build_progressive_mesh(
      repair_mesh(read_mesh(testing::test_data("pymeshlab-colored-airplane-11k.ply"))), {});
  return pm;
}

TEST(PmOperations, GeomorphEndsAreTheTwoLevels) {
  const ProgressiveMesh& pm = airplane_pm();
  const size_t coarse = level_for_faces(pm, 500), fine = level_for_faces(pm, 4000);
  const Geomorph morph = make_geomorph(pm, coarse, fine);
  const Mesh fine_level = level_of_detail(pm, fine);
  const MeshDifference at_one = compare_meshes_exact(morph.at(1.0), fine_level, true);
  EXPECT_TRUE(at_one.equal) << at_one.first_difference;

  // At alpha 0 every vertex sits on its ancestor's coarse position: dropping the faces that
  // collapsed to a point or an edge leaves exactly the coarse level's surface.
  const Mesh at_zero = morph.at(0.0);
  const Mesh coarse_level = level_of_detail(pm, coarse);
  auto face_key = [](const Mesh& m, const Triangle& t) {
    std::array<Vec3, 3> p{m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]};
    std::rotate(p.begin(), std::min_element(p.begin(), p.end()), p.end());
    return p;
  };
  std::vector<std::array<Vec3, 3>> morphed, expected;
  for (const Triangle& t : at_zero.faces) {
    const auto k = face_key(at_zero, t);
    if (k[0] != k[1] && k[1] != k[2] && k[0] != k[2]) morphed.push_back(k);
  }
  for (const Triangle& t : coarse_level.faces) expected.push_back(face_key(coarse_level, t));
  std::sort(morphed.begin(), morphed.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(morphed, expected);
}

TEST(PmOperations, SelectiveRefinementAllOrNothing) {
  const ProgressiveMesh& pm = airplane_pm();
  const auto all = selectively_refine(pm, [](VertexId, const Vec3&) { return true; });
  EXPECT_EQ(all.applied, pm.splits.size());
  EXPECT_TRUE(compare_meshes_exact(all.mesh, level_of_detail(pm, pm.splits.size()), true).equal);
  const auto none = selectively_refine(pm, [](VertexId, const Vec3&) { return false; });
  EXPECT_EQ(none.applied, 0u);
  EXPECT_EQ(none.mesh.face_count(), pm.base.face_count());
}

TEST(PmOperations, SelectiveRefinementOfOneHalf) {
  // Refine the coarse levels everywhere (the vertices of the base and of the first 200
  // splits), then only where x > 0: splits whose vs, vl or vr were never created are
  // skipped, and the result is still a valid mesh.
  const ProgressiveMesh& pm = airplane_pm();
  const VertexId coarse = VertexId(pm.base.vertex_count() + 200);
  const Box box = bounding_box(pm.base);
  const double middle = 0.5 * (box.min[0] + box.max[0]);
  const auto half = selectively_refine(
      pm, [&](VertexId vs, const Vec3& p) { return vs < coarse || p[0] > middle; });
  EXPECT_GT(half.applied, 0u);
  EXPECT_GT(half.skipped_by_predicate + half.skipped_absent, 0u);
  EXPECT_EQ(
      half.applied + half.skipped_absent + half.skipped_by_predicate + half.skipped_inapplicable,
      pm.splits.size());
  EXPECT_GT(half.mesh.face_count(), pm.base.face_count());
  EXPECT_LT(half.mesh.face_count(), pm.full_face_count());
  for (const Triangle& t : half.mesh.faces)
    for (VertexId v : t) ASSERT_LT(v, half.mesh.vertex_count());
}

TEST(PmOperations, UndoWalksBackExactly) {
  const ProgressiveMesh& pm = airplane_pm();
  PmCursor cursor(pm);
  const Mesh base = cursor.extract();
  cursor.go_to_level(pm.splits.size());
  cursor.go_to_level(0);
  EXPECT_TRUE(compare_meshes_exact(cursor.extract(), base, true).equal);
}

}  // namespace
}  // namespace parapm
