// The worker's cache of held quadrics (worker/held_quadrics_cache.h): what it kept comes back
// by build and vertex, a vertex it lacks is reported, and its bounds drop whole builds, the
// longest unused first, or those unused too long.
#include <gtest/gtest.h>

#include <thread>

#include "held_quadrics_cache.h"

namespace parapm::worker {
namespace {

QuadricState quadrics_of(std::vector<VertexId> vertices, double weight) {
  QuadricState s;
  for (VertexId v : vertices) {
    s.vertices.push_back(v);
    s.quadrics.push_back(Quadric::from_plane({0, 0, 1}, -double(v), weight));
  }
  return s;
}

TEST(HeldQuadricsCache, KeepsByBuildAndVertex) {
  HeldQuadricsCache cache(1 << 20, std::chrono::minutes(10));
  cache.keep("a", quadrics_of({1, 5, 9}, 1));
  cache.keep("b", quadrics_of({5}, 2));
  std::vector<Quadric> out;
  ASSERT_TRUE(cache.find("a", {9, 1}, out));
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].c, 81);
  EXPECT_EQ(out[1].c, 1);
  ASSERT_TRUE(cache.find("b", {5}, out));
  EXPECT_EQ(out[0].weight, 2);
  EXPECT_FALSE(cache.find("a", {1, 2}, out));  // 2 was never kept
  EXPECT_FALSE(cache.find("c", {1}, out));     // nor build c
  EXPECT_TRUE(cache.find("c", {}, out));
  // A later round's value replaces the earlier one.
  cache.keep("a", quadrics_of({5}, 3));
  ASSERT_TRUE(cache.find("a", {5, 9}, out));
  EXPECT_EQ(out[0].weight, 3);
  EXPECT_EQ(cache.bytes(), 4 * HeldQuadricsCache::kEntryBytes);
}

TEST(HeldQuadricsCache, PastItsBoundTheLongestUnusedBuildGoes) {
  HeldQuadricsCache cache(10 * HeldQuadricsCache::kEntryBytes, std::chrono::minutes(10));
  std::vector<Quadric> out;
  cache.keep("old", quadrics_of({1, 2, 3, 4}, 1));
  std::this_thread::sleep_for(std::chrono::milliseconds(2));
  cache.keep("used", quadrics_of({1, 2, 3, 4}, 1));
  std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_TRUE(cache.find("old", {1}, out));  // "old" is now the last used
  std::this_thread::sleep_for(std::chrono::milliseconds(2));
  cache.keep("new", quadrics_of({7, 8, 9}, 1));
  EXPECT_EQ(cache.builds(), 2u);
  EXPECT_FALSE(cache.find("used", {1}, out));
  EXPECT_TRUE(cache.find("old", {1, 2, 3, 4}, out));
  EXPECT_TRUE(cache.find("new", {7, 8, 9}, out));
  // A build alone over the bound is not kept at all.
  cache.keep("huge", quadrics_of({1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}, 1));
  EXPECT_FALSE(cache.find("huge", {1}, out));
  EXPECT_LE(cache.bytes(), 10 * HeldQuadricsCache::kEntryBytes);
  // Nothing at all with no memory.
  HeldQuadricsCache none(0, std::chrono::minutes(10));
  none.keep("a", quadrics_of({1}, 1));
  EXPECT_FALSE(none.find("a", {1}, out));
  EXPECT_EQ(none.builds(), 0u);
}

TEST(HeldQuadricsCache, ABuildUnusedTooLongIsDropped) {
  HeldQuadricsCache cache(1 << 20, std::chrono::seconds(1));
  std::vector<Quadric> out;
  cache.keep("idle", quadrics_of({1}, 1));
  cache.keep("busy", quadrics_of({1}, 1));
  for (int i = 0; i < 6; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    ASSERT_TRUE(cache.find("busy", {1}, out));
  }
  EXPECT_FALSE(cache.find("idle", {1}, out));
  EXPECT_EQ(cache.builds(), 1u);
}

}  // namespace
}  // namespace parapm::worker
