// Components that vanish (unless SimplifyOptions::keep_components): a scene of many
// small open parts over a large open ground simplifies below one triangle per part, as the
// parts' last triangles collapse away, and every path that makes the PM (the sequential build,
// the parallel build's final pass) still gives back the input exactly; its levels apply and
// undo, refine selectively, and survive the .pm file. With keep_components every part keeps a
// triangle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>

#include "drawn_meshes.h"
#include "mesh/repaired_input.h"
#include "parallel_test_support.h"
#include "pm/levels.h"
#include "pm/mesh_compare.h"
#include "pm/pm_cursor.h"
#include "pm/pm_file.h"
#include "pm/pm_restore.h"
#include "pm/selective_refinement.h"
#include "simplify/collapse_mesh.h"
#include "simplify/simplify.h"

namespace parapm::testing {
namespace {

constexpr int kPatches = 150;  // each a component of 8 faces, over a ground of 128

// Components of a level that have faces.
uint32_t components_with_faces(const Mesh& level) {
  CollapseMesh cm(level);
  std::vector<uint32_t> component;
  return connected_components(cm, component);
}

ProgressiveMesh build(const RepairedMesh& repaired, const SimplifyOptions& options, uint32_t p) {
  return build_with_subsets(repaired, options, p, 100);  // rounds on this small scene too
}

TEST(VanishingComponents, SmallOpenPartsVanishAndComeBackExactly) {
  const RepairedMesh repaired = repair_mesh(ground_with_patches(kPatches));
  const Mesh input = repaired_input(repaired);
  ASSERT_EQ(components_with_faces(input), uint32_t(kPatches + 1));
  for (const char* metric : {"quadric", "energy"}) {
    for (uint32_t p : {1u, 4u}) {
      const std::string what = std::string(metric) + " p=" + std::to_string(p);
      SimplifyOptions options;
      options.metric = metric;
      options.target_faces = 40;
      const ProgressiveMesh pm = build(repaired, options, p);
      const Mesh base = level_of_detail(pm, 0);
      std::printf("%s: base %zu faces in %u components (input %zu in %d)\n", what.c_str(),
                  base.face_count(), components_with_faces(base), input.face_count(), kPatches + 1);
      EXPECT_LE(base.face_count(), 40u) << what;
      EXPECT_GE(base.face_count(), 1u) << what << ": the largest component stays";
      EXPECT_LT(components_with_faces(base), uint32_t(kPatches / 2)) << what;
      // The ground, the dearest part to lose, is there with its corners.
      for (const Vec3& corner :
           {Vec3{0, 0, 0}, Vec3{100, 0, 0}, Vec3{100, 100, 0}, Vec3{0, 100, 0}})
        EXPECT_NE(std::find(base.positions.begin(), base.positions.end(), corner),
                  base.positions.end())
            << what << " lost the ground's corner " << corner[0] << ", " << corner[1];

      const MeshDifference restored = compare_meshes_exact(restore_input(pm), input, false);
      EXPECT_TRUE(restored.equal) << what << ": " << restored.first_difference;
      std::ostringstream file;
      write_pm(pm, file);
      std::istringstream in(file.str());
      const ProgressiveMesh read = read_pm(in);
      EXPECT_TRUE(compare_meshes_exact(restore_input(read), input, false).equal) << what;

      // Every level on the way up and back down.
      PmCursor cursor(pm);
      while (cursor.level() < cursor.max_level()) cursor.apply_next();
      EXPECT_EQ(cursor.face_count(), input.face_count()) << what;
      while (cursor.level() > 0) cursor.undo_last();
      EXPECT_EQ(cursor.faces(), base.faces) << what;
      // Half of the scene refined: the parts there come back, the others stay away.
      const SelectiveRefinement half =
          selectively_refine(pm, [](VertexId, const Vec3& at) { return at[0] < 50; });
      EXPECT_GT(half.applied, 0u) << what;
      EXPECT_GT(half.mesh.face_count(), base.face_count()) << what;
      EXPECT_LT(half.mesh.face_count(), input.face_count()) << what;
    }
  }
}

TEST(VanishingComponents, KeptWhenAsked) {
  const RepairedMesh repaired = repair_mesh(ground_with_patches(kPatches));
  for (const char* metric : {"quadric", "energy"}) {
    SimplifyOptions options;
    options.metric = metric;
    options.target_faces = 40;
    options.keep_components = true;
    for (uint32_t p : {1u, 4u}) {
      const ProgressiveMesh pm = build(repaired, options, p);
      EXPECT_EQ(components_with_faces(level_of_detail(pm, 0)), uint32_t(kPatches + 1))
          << metric << " p=" << p;
      EXPECT_GE(pm.base.face_count(), size_t(kPatches + 1)) << metric << " p=" << p;
    }
  }
}

}  // namespace
}  // namespace parapm::testing
