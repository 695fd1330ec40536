// Seam collapses (Simplifier::join_copies): the repair's copies of a non-manifold input vertex
// leave the mesh group by group. Three sheets meeting along one line (every spine edge
// non-manifold) simplify below what locked copies allow, the sheets meet at the base and at
// every level but inside one seam collapse, and every path that makes the PM (the sequential
// build, the parallel build's final pass) gives back the input exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "drawn_meshes.h"
#include "mesh/repaired_input.h"
#include "parallel_test_support.h"
#include "pm/copy_separation.h"
#include "pm/levels.h"
#include "pm/mesh_compare.h"
#include "pm/pm_restore.h"
#include "simplify/copy_groups.h"
#include "simplify/simplify.h"

namespace parapm::testing {
namespace {

constexpr int kSheets = 3, kLength = 24, kWidth = 6;

TEST(SeamCollapses, CopyGroupsAreTheRepairsCopies) {
  const RepairedMesh repaired = repair_mesh(book_of_sheets(kSheets, kLength, kWidth));
  const CopyGroups groups = copy_groups(repaired);
  ASSERT_EQ(groups.offsets.size(), size_t(kLength + 2));  // one group per spine vertex
  for (uint32_t g = 0; g + 1 < groups.offsets.size(); ++g) {
    const auto members = groups.of(g);
    ASSERT_EQ(members.size(), size_t(kSheets));
    for (VertexId v : members) {
      EXPECT_EQ(groups.group[v], g);
      EXPECT_EQ(repaired.input_vertex[v], repaired.input_vertex[members[0]]);
      EXPECT_EQ(repaired.mesh.positions[v], repaired.mesh.positions[members[0]]);
    }
    EXPECT_TRUE(std::is_sorted(members.begin(), members.end()));
  }
  EXPECT_TRUE(copy_groups(repair_mesh(book_of_sheets(1, kLength, kWidth))).empty())
      << "one sheet is a manifold mesh: no copies";
}

TEST(SeamCollapses, SheetsMeetingOnALineSimplifyTogether) {
  const RepairedMesh repaired = repair_mesh(book_of_sheets(kSheets, kLength, kWidth));
  ASSERT_EQ(repaired.report.vertex_copies_added, uint64_t(kSheets - 1) * (kLength + 1));
  const Mesh input = repaired_input(repaired);
  for (const char* metric : {"quadric", "energy"}) {
    for (uint32_t p : {1u, 4u}) {
      const std::string what = std::string(metric) + " p=" + std::to_string(p);
      SimplifyOptions options;
      options.metric = metric;
      options.target_faces = 30;
      const ProgressiveMesh pm = build_with_subsets(repaired, options, p, 50);

      // Locked copies keep every spine edge in each sheet: at least kSheets * kLength faces.
      EXPECT_LT(pm.base.face_count(), size_t(kSheets * kLength)) << what;
      // The sheets meet at the base, and at every level but inside a seam collapse, whose
      // records follow one another: kSheets - 1 levels at most between two that meet.
      EXPECT_EQ(copy_separation(pm, 0).parted, 0u) << what;
      size_t run = 0, longest_run = 0, levels_parted = 0;
      for (size_t level = 0; level <= pm.splits.size(); ++level) {
        run = copy_separation(pm, level).parted > 0 ? run + 1 : 0;
        longest_run = std::max(longest_run, run);
        levels_parted += run > 0;
      }
      std::printf("%s: base %zu faces (input %zu); %zu of %zu levels part copies\n", what.c_str(),
                  pm.base.face_count(), input.face_count(), levels_parted, pm.splits.size() + 1);
      EXPECT_LE(longest_run, size_t(kSheets - 1)) << what;

      const MeshDifference restored = compare_meshes_exact(restore_input(pm), input, false);
      EXPECT_TRUE(restored.equal) << what << ": " << restored.first_difference;
    }
  }
}

// A double-sided sheet (every face laid back to back with its reverse): the repair keeps each
// side joined, the two sides meeting at the rim, and the copies of the inside vertices (a
// front and a back one) leave together, so the sides simplify as one and never part.
TEST(SeamCollapses, TheTwoSidesOfADoubleSidedSheetSimplifyTogether) {
  const RepairedMesh repaired = repair_mesh(double_sided(book_of_sheets(1, kLength, kWidth)));
  ASSERT_GT(repaired.report.vertex_copies_added, 0u);
  const Mesh input = repaired_input(repaired);
  for (const char* metric : {"quadric", "energy"}) {
    for (uint32_t p : {1u, 4u}) {
      const std::string what = std::string(metric) + " p=" + std::to_string(p);
      SimplifyOptions options;
      options.metric = metric;
      options.target_faces = 40;
      const ProgressiveMesh pm = build_with_subsets(repaired, options, p, 50);
      std::printf("%s: double-sided sheet, base %zu faces (input %zu)\n", what.c_str(),
                  pm.base.face_count(), input.face_count());
      EXPECT_LE(pm.base.face_count(), 40u) << what;
      EXPECT_EQ(copy_separation(pm, 0).parted, 0u) << what << ": the sides meet";
      const MeshDifference restored = compare_meshes_exact(restore_input(pm), input, false);
      EXPECT_TRUE(restored.equal) << what << ": " << restored.first_difference;
    }
  }
}

// With free copies the sheets simplify apart (no seam collapses): the base parts them.
TEST(SeamCollapses, NotWithFreeCopies) {
  const RepairedMesh repaired = repair_mesh(book_of_sheets(kSheets, kLength, kWidth));
  SimplifyOptions options;
  options.target_faces = 30;
  options.free_copies = true;
  const ProgressiveMesh pm = build_progressive_mesh(repaired, options);
  EXPECT_GT(copy_separation(pm, 0).parted, 0u);
  EXPECT_TRUE(compare_meshes_exact(restore_input(pm), repaired_input(repaired), false).equal);
}

}  // namespace
}  // namespace parapm::testing
