// SimplifyOptions::free_copies: the repair's copies of a non-manifold input vertex simplify like
// any vertex. The PM stays lossless (sequential and parallel), coarse levels reach further, and
// copy_separation (engine/pm/copy_separation.h) measures how far the sheets part: not at all at
// the base by default (the copies leave together: seam collapses), somewhat with free ones.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "io/mesh_io.h"
#include "measure/surface_distance.h"
#include "mesh/repaired_input.h"
#include "parallel/parallel_build.h"
#include "parallel_test_support.h"
#include "pm/copy_separation.h"
#include "pm/levels.h"
#include "pm/mesh_compare.h"
#include "pm/pm_restore.h"
#include "simplify/simplify.h"

namespace parapm::testing {
namespace {

void expect_lossless(const ProgressiveMesh& pm, const RepairedMesh& repaired,
                     const std::string& what) {
  const MeshDifference diff =
      compare_meshes_exact(restore_input(pm), repaired_input(repaired), false);
  EXPECT_TRUE(diff.equal) << what << ": " << diff.first_difference;
}

// The 43k-face CAD part has non-manifold vertices, whose copies set its legal minimum.
TEST(FreeCopies, ReachFurtherAndStayLosslessOnACadPart) {
  const RepairedMesh repaired = repaired_test_mesh("cad-cycloidal-43k.ply");
  ASSERT_GT(repaired.report.vertex_copies_added, 0u) << "the test needs a non-manifold input";
  for (const char* metric : {"quadric", "energy"}) {
    SimplifyOptions options;
    options.metric = metric;
    const ProgressiveMesh locked = build_progressive_mesh(repaired, options);
    options.free_copies = true;
    const ProgressiveMesh free = build_progressive_mesh(repaired, options);
    expect_lossless(locked, repaired, std::string(metric) + " locked");
    expect_lossless(free, repaired, std::string(metric) + " free");
    EXPECT_LT(free.base.face_count(), locked.base.face_count()) << metric;

    // By default the copies meet at the base, and at every level but inside a seam collapse's
    // records (this middle level is not: SeamCollapses.* check every level); free ones part.
    const CopySeparation locked_base = copy_separation(locked, 0);
    EXPECT_EQ(locked_base.pairs, repaired.report.vertex_copies_added) << metric;
    EXPECT_EQ(locked_base.parted, 0u) << metric;
    const CopySeparation locked_mid = copy_separation(locked, locked.splits.size() / 2);
    EXPECT_EQ(locked_mid.parted, 0u) << metric;
    const CopySeparation free_base = copy_separation(free, 0);
    EXPECT_GT(free_base.parted, 0u) << metric;
    // At full resolution every copy is back on its original's position.
    EXPECT_EQ(copy_separation(free, free.splits.size()).parted, 0u) << metric;
    const CopySeparation free_tenth =
        copy_separation(free, level_for_faces(free, repaired.mesh.face_count() / 10));
    std::printf(
        "cad-cycloidal-43k %s: base %zu faces locked, %zu free; copies parted at 10%%: %zu of "
        "%zu, max %.3g, mean %.3g (diagonal %.3g)\n",
        metric, locked.base.face_count(), free.base.face_count(), free_tenth.parted,
        free_tenth.pairs, free_tenth.max, free_tenth.mean, bounding_box(repaired.mesh).diagonal());
  }
  // The parallel build takes the option too (the jobs carry no locks then).
  SimplifyOptions options;
  options.metric = "quadric";
  options.free_copies = true;
  ParallelOptions parallel;
  parallel.subsets = 4;
  const ProgressiveMesh pm = build_progressive_mesh_parallel(repaired, options, parallel);
  expect_lossless(pm, repaired, "parallel p=4 free");
  EXPECT_LT(pm.base.face_count(),
            build_progressive_mesh(repaired, SimplifyOptions{}).base.face_count());
}

// The 203k dragon: 5074 copies of its non-manifold vertices. Free, its 10% level is closer to
// the input (the engine's surface distance; metro agrees,
// docs/decisions/notebook-2026-11.md).
TEST(FreeCopies, BringTheDragonsTenthLevelCloser) {
  const std::filesystem::path path = shared_meshes_dir() / "stanford-dragon-res2-203k.ply.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "../shared/meshes is not present";
  const RepairedMesh repaired = repair_mesh(read_mesh(path.string()));
  const Mesh input = repaired_input(repaired);
  const size_t tenth = repaired.mesh.face_count() / 10;
  SimplifyOptions options;
  options.metric = "energy";
  options.target_faces = tenth;
  const ProgressiveMesh locked = build_progressive_mesh(repaired, options);
  options.free_copies = true;
  const ProgressiveMesh free = build_progressive_mesh(repaired, options);
  expect_lossless(free, repaired, "dragon free");
  const double locked_rms = surface_distance(input, locked.base, 20000).rms;
  const double free_rms = surface_distance(input, free.base, 20000).rms;
  const CopySeparation parted = copy_separation(free, 0);
  std::printf(
      "dragon 203k energy at %zu faces: RMS %.3g locked, %.3g free; %zu of %zu copies "
      "parted, max %.3g, mean %.3g (diagonal %.3g)\n",
      tenth, locked_rms, free_rms, parted.parted, parted.pairs, parted.max, parted.mean,
      bounding_box(repaired.mesh).diagonal());
  EXPECT_LT(free_rms, locked_rms);
}

}  // namespace
}  // namespace parapm::testing
