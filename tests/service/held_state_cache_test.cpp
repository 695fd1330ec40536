// The worker's cache of held state (worker/held_state_cache.h): what it kept comes back by
// build and vertex or point, one it lacks is reported, and its bounds drop whole builds, the
// longest unused first, or those unused too long.
#include <gtest/gtest.h>

#include <thread>

#include "held_state_cache.h"

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

TEST(HeldStateCache, KeepsByBuildAndVertex) {
  HeldStateCache cache(1 << 20, std::chrono::minutes(10));
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
  EXPECT_EQ(cache.bytes(), 4 * HeldStateCache::kQuadricBytes);
  // A job may name no more held items than a build holds.
  EXPECT_EQ(cache.item_bound("a"), 3u);
  EXPECT_EQ(cache.item_bound("c"), 0u);
}

TEST(HeldStateCache, KeepsPointsById) {
  HeldStateCache cache(1 << 20, std::chrono::minutes(10));
  EnergyState state;
  for (uint32_t id : {7u, 2u, 40u}) {
    EnergyState::Point p;
    p.id = id;
    p.position = {double(id), 1, 2};
    p.distance_sq = id / 10.0;
    state.points.push_back(p);
    state.point_values.insert(state.point_values.end(), {float(id), 0.5f});
  }
  cache.keep_points("a", state);
  std::vector<HeldPoint> positions;
  std::vector<float> values;
  ASSERT_TRUE(cache.find_points("a", {40, 7}, 2, positions, values));
  ASSERT_EQ(positions.size(), 2u);
  EXPECT_EQ(positions[0].position, (Vec3{40, 1, 2}));
  EXPECT_EQ(positions[1].position, (Vec3{7, 1, 2}));
  EXPECT_EQ(positions[1].distance_sq, 0.7);
  EXPECT_EQ(values, (std::vector<float>{40, 0.5f, 7, 0.5f}));
  // A job's returned distances replace the kept ones (a point never kept is not added).
  EnergyState returned;
  returned.positions = false;
  returned.points = {state.points[0], state.points[0]};
  returned.points[0].distance_sq = 9;
  returned.points[1].id = 5;
  cache.update_points("a", returned);
  ASSERT_TRUE(cache.find_points("a", {7}, 2, positions, values));
  EXPECT_EQ(positions[0].distance_sq, 9);
  EXPECT_EQ(positions[0].position, (Vec3{7, 1, 2}));
  EXPECT_FALSE(cache.find_points("a", {3}, 2, positions, values));   // never kept
  EXPECT_FALSE(cache.find_points("a", {41}, 2, positions, values));  // past them all
  EXPECT_FALSE(cache.find_points("a", {7}, 3, positions, values));   // kept with 2 values
  EXPECT_FALSE(cache.find_points("b", {7}, 2, positions, values));
  EXPECT_FALSE(cache.find_points("a", {5}, 2, positions, values));
  EXPECT_EQ(cache.bytes(), 41 * (HeldStateCache::kPointBytes + 8));
  EXPECT_EQ(cache.item_bound("a"), 41u);  // the ids up to the largest
  // Points beyond what the whole cache could hold are not kept.
  HeldStateCache small(100 * HeldStateCache::kPointBytes, std::chrono::minutes(10));
  state.points[2].id = 1000;
  small.keep_points("a", state);
  EXPECT_FALSE(small.find_points("a", {7}, 2, positions, values));
}

TEST(HeldStateCache, PastItsBoundTheLongestUnusedBuildGoes) {
  HeldStateCache cache(10 * HeldStateCache::kQuadricBytes, std::chrono::minutes(10));
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
  EXPECT_LE(cache.bytes(), 10 * HeldStateCache::kQuadricBytes);
  // Nothing at all with no memory.
  HeldStateCache none(0, std::chrono::minutes(10));
  none.keep("a", quadrics_of({1}, 1));
  EXPECT_FALSE(none.find("a", {1}, out));
  EXPECT_EQ(none.builds(), 0u);
}

TEST(HeldStateCache, ABuildUnusedTooLongIsDropped) {
  HeldStateCache cache(1 << 20, std::chrono::seconds(1));
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
