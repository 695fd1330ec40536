// Selective refinement: the presence rule, the predicate, and the two extremes (all splits,
// none) against the full-resolution and base meshes.
#include "pm/selective_refinement.h"

#include <gtest/gtest.h>

#include "pm/levels.h"
#include "pm/mesh_compare.h"
#include "pm_fixtures.h"
#include "test_support.h"

namespace parapm {
namespace {

std::vector<ProgressiveMesh> all_fixtures() {
  std::vector<ProgressiveMesh> pms = {testing::strip_pm(), testing::octahedron_pm(false),
                                      testing::octahedron_pm(true), testing::cut_fan_pm()};
  for (bool closed : {true, false})
    for (bool attributes : {false, true})
      pms.push_back(testing::random_pm(400, {closed, attributes, !attributes, 21}));
  return pms;
}

TEST(SelectiveRefinement, AlwaysTrueGivesTheFullMesh) {
  for (const ProgressiveMesh& pm : all_fixtures()) {
    const SelectiveRefinement r =
        selectively_refine(pm, [](VertexId, const Vec3&) { return true; });
    EXPECT_EQ(r.applied, pm.splits.size());
    EXPECT_EQ(r.skipped_absent + r.skipped_by_predicate + r.skipped_inapplicable, 0u);
    const MeshDifference d =
        compare_meshes_exact(r.mesh, level_of_detail(pm, pm.splits.size()), true);
    EXPECT_TRUE(d.equal) << d.first_difference;
    EXPECT_EQ(r.pm_vertex.size(), pm.full_vertex_count());
  }
}

TEST(SelectiveRefinement, AlwaysFalseGivesTheBaseMesh) {
  for (const ProgressiveMesh& pm : all_fixtures()) {
    const SelectiveRefinement r =
        selectively_refine(pm, [](VertexId, const Vec3&) { return false; });
    EXPECT_EQ(r.applied, 0u);
    EXPECT_EQ(r.skipped_absent + r.skipped_by_predicate, pm.splits.size());
    const MeshDifference d = compare_meshes_exact(r.mesh, level_of_detail(pm, 0), true);
    EXPECT_TRUE(d.equal) << d.first_difference;
  }
}

TEST(SelectiveRefinement, SplitsOfAbsentVerticesAreSkipped) {
  // Octahedron: split 0 splits 4 (creating 6), split 1 splits 5 (creating 7), split 2 splits 6.
  const ProgressiveMesh pm = testing::octahedron_pm(true);
  std::vector<VertexId> asked;
  const SelectiveRefinement r = selectively_refine(pm, [&](VertexId vs, const Vec3& p) {
    asked.push_back(vs);
    if (vs == 5) {
      EXPECT_EQ(p, (Vec3{0, 0, -1}));
    }
    return vs != 4;
  });
  EXPECT_EQ(asked, (std::vector<VertexId>{4, 5}));  // never asked about 6: it is absent
  EXPECT_EQ(r.applied, 1u);
  EXPECT_EQ(r.skipped_by_predicate, 1u);
  EXPECT_EQ(r.skipped_absent, 1u);
  EXPECT_EQ(r.pm_vertex, (std::vector<VertexId>{0, 1, 2, 3, 4, 5, 7}));
  EXPECT_EQ(r.mesh.vertex_count(), 7u);
  EXPECT_EQ(r.mesh.face_count(), 10u);
  EXPECT_TRUE(testing::is_oriented_manifold(r.mesh.faces));
  // Vertex 7 of the PM is vertex 6 of the result; split 1's fl = (5,7,3) is the 9th face.
  EXPECT_EQ(r.mesh.faces[8], (Triangle{5, 6, 3}));
  EXPECT_EQ(r.mesh.positions[6], (Vec3{0.25, 0, -1}));
}

TEST(SelectiveRefinement, ApplyingTheFirstKSplitsGivesLevelK) {
  const ProgressiveMesh pm = testing::random_pm(300, {false, true, true, 8});
  for (size_t k : {size_t(0), size_t(1), size_t(77), size_t(300)}) {
    size_t calls = 0;
    const SelectiveRefinement r =
        selectively_refine(pm, [&](VertexId, const Vec3&) { return calls++ < k; });
    EXPECT_EQ(r.applied, k);
    const MeshDifference d = compare_meshes_exact(r.mesh, level_of_detail(pm, k), true);
    EXPECT_TRUE(d.equal) << k << ": " << d.first_difference;
  }
}

TEST(SelectiveRefinement, RegionalRefinementStaysManifold) {
  for (bool closed : {true, false}) {
    const ProgressiveMesh pm = testing::random_pm(2000, {closed, false, true, 13});
    const SelectiveRefinement r =
        selectively_refine(pm, [](VertexId, const Vec3& p) { return p[0] > 0.3; });
    EXPECT_GT(r.applied, 0u);
    EXPECT_GT(r.skipped_absent + r.skipped_by_predicate, 0u);
    EXPECT_EQ(r.applied + r.skipped_absent + r.skipped_by_predicate + r.skipped_inapplicable,
              pm.splits.size());
    EXPECT_TRUE(testing::is_oriented_manifold(r.mesh.faces));
    EXPECT_EQ(r.mesh.vertex_count(), pm.base.vertex_count() + r.applied);
  }
}

TEST(SelectiveRefinement, SplitsThatDoNotFitAreSkippedNotFatal) {
  // A split whose vl is present but not adjacent to vs (only a corrupt or reordered PM has
  // one): selective refinement counts it, where PmCursor would throw.
  ProgressiveMesh pm = testing::octahedron_pm();
  pm.splits[1].vl = 4;  // the top vertex, not a neighbour of the bottom one
  const SelectiveRefinement r = selectively_refine(pm, [](VertexId, const Vec3&) { return true; });
  EXPECT_EQ(r.skipped_inapplicable, 1u);
  EXPECT_EQ(r.applied, 2u);
  EXPECT_TRUE(testing::is_oriented_manifold(r.mesh.faces));
}

}  // namespace
}  // namespace parapm
