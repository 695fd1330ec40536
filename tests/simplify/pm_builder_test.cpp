// build_pm_from_collapses (pm_builder.h) in chunks side by side: the PM of one pass, byte for
// byte, on meshes with and without attributes, and the vertex splits give back the input.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "mesh/repaired_input.h"
#include "pm/mesh_compare.h"
#include "pm/pm_file.h"
#include "pm/pm_restore.h"
#include "simplify/copy_groups.h"
#include "simplify/modules.h"
#include "simplify/pm_builder.h"
#include "simplify/simplify.h"
#include "test_support.h"

namespace parapm {
namespace {

TEST(PmBuilder, InChunksTheSamePmAsInOnePass) {
  for (const char* name : {"pymeshlab-bunny-textured-10k.obj", "pymeshlab-colored-airplane-11k.ply",
                           "cad-cycloidal-43k.ply"}) {
    SCOPED_TRACE(name);
    const RepairedMesh repaired = repair_mesh(read_mesh(testing::test_data(name)));
    SimplifyOptions options;
    options.metric = "quadric";
    options.target_ratio = 0.05;
    const std::vector<uint8_t> on_membrane = membrane_vertices(repaired);
    const CopyGroups groups = copy_groups(repaired, on_membrane);
    const std::vector<uint8_t> locked = locked_vertices(groups, repaired.mesh.vertex_count());
    CollapseMesh working(repaired.mesh);
    const auto priority = make_priority_module(options, repaired.mesh, locked);
    Simplifier simplifier(working, *priority, standard_constraints(locked, {}, true, on_membrane));
    if (!groups.empty()) simplifier.join_copies(&groups);
    SimplifierLimits limits;
    limits.target_faces = target_face_count(repaired.mesh.face_count(), options);
    const std::vector<CollapseRecord> records = simplifier.run(limits, {}, nullptr);
    ASSERT_GT(records.size(), repaired.mesh.vertex_count() / 2);

    const ProgressiveMesh one_pass = build_pm_from_collapses(repaired, working, records, {});
    const std::string expected = testing::pm_bytes(one_pass);
    const MeshDifference restored =
        compare_meshes_exact(restore_input(one_pass), repaired_input(repaired), false);
    EXPECT_TRUE(restored.equal) << restored.first_difference;
    for (auto [chunks, threads, min_chunk] : {std::tuple{7u, 2u, 16u}, std::tuple{3u, 3u, 1u}}) {
      ChunkedLoops loops(chunks, threads, min_chunk);
      PmBuildOptions in_chunks;
      in_chunks.loops = &loops;
      EXPECT_TRUE(testing::pm_bytes(
                      build_pm_from_collapses(repaired, working, records, in_chunks)) == expected)
          << chunks << " chunks";
    }
  }
}

}  // namespace
}  // namespace parapm
