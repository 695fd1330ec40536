// Membranes (copy_groups.h): a part every vertex of which is a repair copy of a vertex of a
// part with vertices of its own, and which fills no hole of it, holds no copy group: its
// vertices simplify like any vertex and it may vanish, while the surface it lies on simplifies
// as if it were not there. A sphere with back faces laid on it (the repair cuts each off alone,
// the sphere staying closed): locked, the back faces' copies would pin the sphere's vertices
// and each back face would keep its triangle; the PM still gives back the input exactly.
#include <gtest/gtest.h>

#include <cstdio>
#include <numeric>
#include <string>

#include "drawn_meshes.h"
#include "measure/surface_distance.h"
#include "mesh/mesh_checks.h"
#include "mesh/repaired_input.h"
#include "parallel_test_support.h"
#include "pm/levels.h"
#include "pm/mesh_compare.h"
#include "pm/pm_restore.h"
#include "simplify/copy_groups.h"
#include "simplify/simplify.h"

namespace parapm::testing {
namespace {

constexpr int kRings = 16, kSegments = 24, kEvery = 7;

size_t back_faces() {
  const Mesh mesh = uv_sphere_with_back_faces(kRings, kSegments, kEvery);
  return mesh.faces.size() - uv_sphere(kRings, kSegments).faces.size();
}

size_t flagged(const std::vector<uint8_t>& flags) {
  return size_t(std::accumulate(flags.begin(), flags.end(), 0u));
}

TEST(Membranes, BackFacesLaidOnASphereHoldNoCopyGroup) {
  const RepairedMesh repaired = repair_mesh(uv_sphere_with_back_faces(kRings, kSegments, kEvery));
  ASSERT_EQ(repaired.report.vertex_copies_added, 3 * back_faces());
  EXPECT_EQ(topology_stats(repaired.mesh).boundary_edges, 3 * back_faces())
      << "the sphere stays closed; the back faces are lone triangles";
  EXPECT_EQ(flagged(membrane_vertices(repaired)), 3 * back_faces());
  EXPECT_TRUE(copy_groups(repaired).empty()) << "every copy lies on a back face";
  EXPECT_EQ(flagged(locked_vertices(repaired)), 0u);
}

// A back face alone in a hole of the sphere fills it: no membrane, its copies locked with the
// sphere's rim (its vanishing would open the hole).
TEST(Membranes, NotAFaceFillingAHole) {
  const RepairedMesh repaired =
      repair_mesh(uv_sphere_with_back_faces(kRings, kSegments, kEvery, true));
  EXPECT_EQ(flagged(membrane_vertices(repaired)), 3 * (back_faces() - 1));
  EXPECT_EQ(flagged(locked_vertices(repaired)), 6u) << "the filling face's and the rim's";
}

// The two sides of a double-sided sheet are copies of each other, neither a membrane: they
// keep their groups (and move only together).
TEST(Membranes, NotTheTwoSidesOfADoubleSidedSheet) {
  const RepairedMesh repaired = repair_mesh(double_sided(book_of_sheets(1, 8, 4)));
  ASSERT_GT(repaired.report.vertex_copies_added, 0u);
  EXPECT_EQ(flagged(membrane_vertices(repaired)), 0u);
  EXPECT_FALSE(copy_groups(repaired).empty());
}

TEST(Membranes, VanishAndTheSphereSimplifiesBelowThemWithoutAHole) {
  const RepairedMesh repaired = repair_mesh(uv_sphere_with_back_faces(kRings, kSegments, kEvery));
  const Mesh input = repaired_input(repaired);
  const Mesh sphere = uv_sphere(kRings, kSegments);
  // Fewer faces than back faces: each locked one would keep its triangle at least.
  const size_t target = back_faces() / 2;
  for (const char* metric : {"quadric", "energy"}) {
    for (uint32_t p : {1u, 4u}) {
      const std::string what = std::string(metric) + " p=" + std::to_string(p);
      SimplifyOptions options;
      options.metric = metric;
      options.target_faces = target;
      const ProgressiveMesh pm = build_with_subsets(repaired, options, p, 50);
      const Mesh base = level_of_detail(pm, 0);
      const double hausdorff = surface_distance(sphere, base, 20000).hausdorff;
      std::printf("%s: base %zu faces (target %zu, %zu back faces); Hausdorff to the sphere %.3g\n",
                  what.c_str(), base.face_count(), target, back_faces(), hausdorff);
      EXPECT_LE(base.face_count(), target) << what;
      const TopologyStats stats = topology_stats(base);
      EXPECT_EQ(stats.boundary_edges, 0u) << what << ": a closed surface, no hole opened";
      EXPECT_EQ(stats.components, 1u) << what << ": the back faces are gone";
      EXPECT_LT(hausdorff, 0.1) << what << ": still the sphere";
      const MeshDifference restored = compare_meshes_exact(restore_input(pm), input, false);
      EXPECT_TRUE(restored.equal) << what << ": " << restored.first_difference;
    }
  }
}

}  // namespace
}  // namespace parapm::testing
