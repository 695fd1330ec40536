// Lists of edge records (simplifier.h): merge_unique_edges gives what sort_unique_edges of the
// lists joined in order gives, the first record of an edge kept, whether the lists are sorted
// (merged, in ranges of first ends side by side or not) or not (sorted).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "simplify/simplifier.h"
#include "util/chunked_loops.h"

namespace parapm {
namespace {

using Lists = std::vector<std::vector<DeferredEdge>>;

std::vector<DeferredEdge> joined_and_sorted(const Lists& lists) {
  std::vector<DeferredEdge> all;
  for (const auto& list : lists) all.insert(all.end(), list.begin(), list.end());
  sort_unique_edges(all);
  return all;
}

std::vector<DeferredEdge> merged(const Lists& lists, ChunkedLoops& loops) {
  std::vector<const std::vector<DeferredEdge>*> pointers;
  for (const auto& list : lists) pointers.push_back(&list);
  return merge_unique_edges(pointers, loops);
}

std::vector<DeferredEdge> merged(const Lists& lists) {
  ChunkedLoops one_thread;
  return merged(lists, one_thread);
}

void expect_same(const std::vector<DeferredEdge>& x, const std::vector<DeferredEdge>& y) {
  ASSERT_EQ(x.size(), y.size());
  for (size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(x[i].a, y[i].a) << i;
    EXPECT_EQ(x[i].b, y[i].b) << i;
    EXPECT_EQ(x[i].key, y[i].key) << i;  // which record of the edge was kept
  }
}

// Random lists over few vertices, so that edges repeat within and across lists; each record's
// key names its list and place.
Lists random_lists(std::mt19937& random, bool sort_each) {
  Lists lists(1 + random() % 6);
  for (size_t l = 0; l < lists.size(); ++l) {
    const size_t n = random() % 40;
    for (size_t i = 0; i < n; ++i) {
      const uint32_t a = random() % 12, b = a + 1 + random() % 5;
      lists[l].push_back({a, b, float(l * 1000 + i)});
    }
    if (sort_each) std::stable_sort(lists[l].begin(), lists[l].end(), ByEdge{});
  }
  return lists;
}

TEST(EdgeLists, MergedAsTheJoinedListsSortedKeepingTheFirstRecord) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 300; ++trial) {
    const Lists lists = random_lists(random, trial % 3 != 0);
    expect_same(merged(lists), joined_and_sorted(lists));
    ChunkedLoops by_first_end(5, 2, 1);  // ranges of first ends, merged side by side
    expect_same(merged(lists, by_first_end), joined_and_sorted(lists));
  }
}

TEST(EdgeLists, AnEdgeInTwoListsKeepsTheEarlierListsRecord) {
  const Lists lists = {{{1, 2, 10}, {3, 4, 11}}, {{1, 2, 20}, {2, 5, 21}}, {}, {{3, 4, 40}}};
  const std::vector<DeferredEdge> out = merged(lists);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].key, 10);
  EXPECT_EQ(out[1].key, 21);
  EXPECT_EQ(out[2].key, 11);
  EXPECT_TRUE(merged({}).empty());
}

}  // namespace
}  // namespace parapm
