// The collapse queue's tiers against one heap of the same items: the same order out, through
// pushes between pops, keys tied, infinite and far apart, removals, and items that die.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "simplify/quad_heap.h"
#include "simplify/tiered_queue.h"

namespace parapm {
namespace {

struct Item {
  float cost;
  uint32_t a, b;
};

struct ItemBefore {
  bool operator()(const Item& x, const Item& y) const {
    if (x.cost != y.cost) return x.cost < y.cost;
    if (x.a != y.a) return x.a < y.a;
    return x.b < y.b;
  }
};

bool same(const Item& x, const Item& y) { return x.cost == y.cost && x.a == y.a && x.b == y.b; }

// Keys as a collapse queue sees them: many tied (flat regions cost 0), most a little above the
// water level, some far above it, a few infinite (refused edges at the end of the queue).
float draw_key(std::mt19937& random, float level) {
  const uint32_t kind = random() % 16;
  if (kind == 0) return 0.0f;
  if (kind == 1) return std::numeric_limits<float>::infinity();
  if (kind == 2) return level + float(random() % 4);  // ties at a few values
  if (kind == 3) return level * 1000.0f + float(random() % 1000000);
  return level + float(random() % 100000) / 1000.0f;
}

TEST(TieredQueue, GivesTheOrderOfOneHeapThroughPushesAndPops) {
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    std::mt19937 random(seed);
    TieredQueue<Item, ItemBefore> tiered;
    QuadHeap<Item, ItemBefore> heap;
    uint32_t id = 0;
    for (int i = 0; i < 60000; ++i) {
      const Item item{draw_key(random, 0.0f), uint32_t(random() % 100000), id++};
      tiered.push(item);
      heap.push(item);
    }
    size_t popped = 0;
    float level = 0;
    while (!heap.empty()) {
      ASSERT_FALSE(tiered.empty());
      ASSERT_EQ(tiered.size(), heap.size());
      ASSERT_TRUE(same(tiered.top(), heap.top())) << "seed " << seed << ", item " << popped;
      const Item out = tiered.pop();
      ASSERT_TRUE(same(out, heap.pop())) << "seed " << seed << ", item " << popped;
      ++popped;
      if (std::isfinite(out.cost)) level = out.cost;
      // A collapse's edges come back around the water level, while the queue is long.
      if (popped % 3 == 0 && popped < 150000) {
        for (int k = 0; k < 4; ++k) {
          const Item item{draw_key(random, level), uint32_t(random() % 100000), id++};
          tiered.push(item);
          heap.push(item);
        }
      }
    }
    EXPECT_TRUE(tiered.empty());
    EXPECT_GT(popped, 200000u);
  }
}

TEST(TieredQueue, RemovesWhatItIsToldAndKeepsTheOrder) {
  std::mt19937 random(7);
  TieredQueue<Item, ItemBefore> tiered;
  QuadHeap<Item, ItemBefore> heap;
  for (uint32_t id = 0; id < 100000; ++id) {
    const Item item{draw_key(random, 0.0f), id, 0};
    tiered.push(item);
    heap.push(item);
  }
  // Removed from both, checked, then popped on: the first time before any pop (the blocks of
  // the open bucket left part-filled for the cut to sample), then from every tier.
  auto remove_from_both = [&](auto drop) {
    const size_t before = tiered.size();
    const size_t removed = tiered.remove_if(drop);
    std::erase_if(heap.items(), drop);
    heap.rebuild();
    EXPECT_EQ(removed, before - heap.size());
    EXPECT_GT(removed, before / 5);
    size_t visited = 0;
    tiered.for_each([&](const Item& item) {
      EXPECT_FALSE(drop(item));
      ++visited;
    });
    EXPECT_EQ(visited, heap.size());
  };
  remove_from_both([](const Item& item) { return item.a % 2 == 1; });
  for (int i = 0; i < 10000; ++i) ASSERT_TRUE(same(tiered.pop(), heap.pop()));
  remove_from_both([](const Item& item) { return item.a % 3 == 0; });
  while (!heap.empty()) ASSERT_TRUE(same(tiered.pop(), heap.pop()));
  EXPECT_TRUE(tiered.empty());
  // Cleared, it starts over.
  tiered.push({1.0f, 1, 1});
  tiered.clear();
  EXPECT_TRUE(tiered.empty());
  tiered.push({2.0f, 2, 2});
  EXPECT_EQ(tiered.pop().a, 2u);
}

// Items that die after they were pushed (a collapse queue's stale entries) and are dropped as
// their range reaches the heap: the live ones come out as one heap, skipping the dead, gives them.
TEST(TieredQueue, DropsDeadItemsAndKeepsTheOrderOfTheLiveOnes) {
  std::mt19937 random(11);
  std::vector<uint8_t> dead;
  TieredQueue<Item, ItemBefore> tiered;
  tiered.drop_when([&](const Item& item) { return dead[item.b] != 0; });
  QuadHeap<Item, ItemBefore> heap;
  auto push = [&](float level) {
    const Item item{draw_key(random, level), uint32_t(random() % 100000), uint32_t(dead.size())};
    dead.push_back(0);
    tiered.push(item);
    heap.push(item);
  };
  size_t dead_from_heap = 0, dead_from_tiers = 0;  // dead items that came out to be skipped
  auto next_live = [&]() -> Item {
    for (;;) {
      const Item out = heap.pop();
      if (!dead[out.b]) return out;
      ++dead_from_heap;
    }
  };
  for (int i = 0; i < 60000; ++i) push(0.0f);
  size_t popped = 0, live_left = 60000;
  float level = 0;
  while (live_left > 0) {
    // The tiered queue may still hold dead items; it gives no live one out of order.
    Item out = tiered.pop();
    for (; dead[out.b]; out = tiered.pop()) ++dead_from_tiers;
    ASSERT_TRUE(same(out, next_live())) << "item " << popped;
    dead[out.b] = 1;  // out of the queue: any copy left is stale
    --live_left;
    ++popped;
    if (std::isfinite(out.cost)) level = out.cost;
    if (popped < 100000 && popped % 2 == 0) {
      // A collapse: some queued items die, new ones come.
      for (int k = 0; k < 3; ++k) {
        const uint32_t victim = uint32_t(random() % dead.size());
        live_left -= !dead[victim];
        dead[victim] = 1;
      }
      for (int k = 0; k < 3; ++k, ++live_left) push(level);
    }
  }
  EXPECT_GT(popped, 50000u);
  EXPECT_LT(dead_from_tiers, dead_from_heap / 2);  // most were dropped on the way
}

}  // namespace
}  // namespace parapm
