// Level selection by face count and by error bound, and level extraction.
#include "pm/levels.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pm/pm_cursor.h"
#include "pm_fixtures.h"
#include "test_support.h"
#include "util/error.h"

namespace parapm {
namespace {

// Octahedron PM: faces 8, 10, 12, 14 at levels 0..3; split errors 3, 2, 2, so
// error(0) = 3, error(1) = 2, error(2) = 2, error(3) = 0.
TEST(Levels, FaceCountAtLevel) {
  const ProgressiveMesh pm = testing::octahedron_pm();
  EXPECT_EQ(face_count_at_level(pm, 0), 8u);
  EXPECT_EQ(face_count_at_level(pm, 3), 14u);
  EXPECT_THROW(face_count_at_level(pm, 4), Error);
  const ProgressiveMesh strip = testing::strip_pm();  // one face per split
  EXPECT_EQ(face_count_at_level(strip, 1), 5u);
  EXPECT_EQ(face_count_at_level(strip, 2), 6u);
}

TEST(Levels, LevelForFacesIsTheLargestThatFits) {
  const ProgressiveMesh pm = testing::octahedron_pm();
  EXPECT_EQ(level_for_faces(pm, 0), 0u);  // nothing fits: the base mesh is the coarsest
  EXPECT_EQ(level_for_faces(pm, 8), 0u);
  EXPECT_EQ(level_for_faces(pm, 9), 0u);
  EXPECT_EQ(level_for_faces(pm, 10), 1u);
  EXPECT_EQ(level_for_faces(pm, 13), 2u);
  EXPECT_EQ(level_for_faces(pm, 14), 3u);
  EXPECT_EQ(level_for_faces(pm, 1000), 3u);
  const ProgressiveMesh strip = testing::strip_pm();
  EXPECT_EQ(level_for_faces(strip, 5), 1u);
}

TEST(Levels, LevelForErrorIsTheSmallestWithinTheBound) {
  const ProgressiveMesh pm = testing::octahedron_pm();
  EXPECT_EQ(level_for_error(pm, 5), 0u);
  EXPECT_EQ(level_for_error(pm, 3), 0u);  // error(0) = 3 <= 3
  EXPECT_EQ(level_for_error(pm, 2.5), 1u);
  EXPECT_EQ(level_for_error(pm, 2), 1u);      // error(1) = 2
  EXPECT_EQ(level_for_error(pm, 1.999), 3u);  // only the full mesh (error 0)
  EXPECT_EQ(level_for_error(pm, 0), 3u);
  EXPECT_EQ(level_for_error(pm, -1), 3u);
  EXPECT_THROW(level_for_error(pm, std::nan("")), Error);
  EXPECT_EQ(level_for_error(ProgressiveMesh{}, 1), 0u);
}

TEST(Levels, LevelForErrorMatchesTheSplitsWhoseErrorExceedsTheBound) {
  const ProgressiveMesh pm = testing::random_pm(400, {true, false, true, 2});
  for (double bound : {0.0, 10.0, 100.0, 500.0, 900.0, 1000.0}) {
    size_t above = 0;
    for (const VertexSplit& s : pm.splits) above += s.error > bound;
    EXPECT_EQ(level_for_error(pm, bound), above) << bound;
  }
}

TEST(Levels, LevelOfDetailExtractsTheLevel) {
  const ProgressiveMesh pm = testing::octahedron_pm(true);
  for (size_t level = 0; level <= 3; ++level) {
    const Mesh m = level_of_detail(pm, level);
    EXPECT_EQ(m.face_count(), face_count_at_level(pm, level));
    EXPECT_EQ(m.vertex_count(), 6 + level);
    EXPECT_EQ(m.face_wedges.size(), m.face_count());
  }
  EXPECT_THROW(level_of_detail(pm, 4), Error);
  const ProgressiveMesh strip = testing::strip_pm();
  EXPECT_EQ(level_of_detail(strip, 2).faces, testing::strip_full_faces());
}

}  // namespace
}  // namespace parapm
