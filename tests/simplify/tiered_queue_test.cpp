// The collapse queue's tiers against one heap of the same items: the same order out, through
// pushes between pops, keys tied, infinite and far apart, removals, and items that die.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "simplify/key_rank.h"
#include "simplify/quad_heap.h"
#include "simplify/tiered_queue.h"

namespace parapm {
namespace {

struct Item {
  float key;
  uint32_t a, b;
};

struct ItemBefore {
  bool operator()(const Item& x, const Item& y) const {
    if (x.key != y.key) return x.key < y.key;
    if (x.a != y.a) return x.a < y.a;
    return x.b < y.b;
  }
};

bool same(const Item& x, const Item& y) { return x.key == y.key && x.a == y.a && x.b == y.b; }

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
      if (std::isfinite(out.key)) level = out.key;
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
    if (std::isfinite(out.key)) level = out.key;
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

// The collapse queue's keys as ranks (key_rank.h): one 64-bit word of rank and first id.
struct RankedItem {
  uint32_t a;
  uint32_t key;
  uint32_t b;
};

struct RankedBefore {
  bool operator()(const RankedItem& x, const RankedItem& y) const {
    const uint64_t kx = uint64_t(x.key) << 32 | x.a, ky = uint64_t(y.key) << 32 | y.a;
    return kx != ky ? kx < ky : x.b < y.b;
  }
};

TEST(KeyRank, OrdersAsTheFloatsAndGivesThemBack) {
  const float inf = std::numeric_limits<float>::infinity();
  const float denormal = std::numeric_limits<float>::denorm_min();
  const float big = std::numeric_limits<float>::max();
  std::vector<float> keys = {-inf,     -big,   -1e20f, -1.5f, -1.0f, -denormal, -0.0f, 0.0f,
                             denormal, 1e-30f, 1.0f,   1.5f,  3e38f, big,       inf};
  std::mt19937 random(5);
  for (int i = 0; i < 2000; ++i)
    keys.push_back(std::ldexp(float(random() % 2000) - 1000.0f, int(random() % 200) - 100));
  for (float x : keys) {
    EXPECT_EQ(rank_key(key_rank(x)), x + 0.0f);
    EXPECT_FALSE(std::signbit(rank_key(key_rank(x))) && x == 0) << "-0 ranks as +0";
    for (float y :
         {-inf, -1.0f, -0.0f, 0.0f, denormal, 1.0f, inf, keys[size_t(random() % keys.size())]}) {
      EXPECT_EQ(key_rank(x) < key_rank(y), x < y) << x << " " << y;
      EXPECT_EQ(key_rank(x) == key_rank(y), x == y) << x << " " << y;
    }
  }
}

TEST(TieredQueue, GivesRankedKeysOutInTheOrderOfTheirFloats) {
  std::mt19937 random(13);
  TieredQueue<RankedItem, RankedBefore> ranked;
  QuadHeap<Item, ItemBefore> heap;
  auto push = [&](float key) {
    // Negative keys too (the simplifier's keys of flat collapses), a few -0 beside +0.
    if (random() % 8 == 0) key = -key;
    const Item item{key, uint32_t(random() % 1000), uint32_t(random() % 100000)};
    ranked.push({item.a, key_rank(item.key), item.b});
    heap.push(item);
  };
  for (int i = 0; i < 50000; ++i) push(draw_key(random, 0.0f));
  size_t popped = 0;
  while (!heap.empty()) {
    const Item want = heap.pop();
    const RankedItem got = ranked.pop();
    ASSERT_TRUE(rank_key(got.key) == want.key && got.a == want.a && got.b == want.b)
        << "item " << popped;
    if (++popped < 40000 && popped % 2 == 0) push(std::isfinite(want.key) ? want.key + 1.0f : 1.0f);
  }
  EXPECT_TRUE(ranked.empty());
}

}  // namespace
}  // namespace parapm
