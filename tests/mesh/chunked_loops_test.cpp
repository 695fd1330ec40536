#include "util/chunked_loops.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "loop_ranges.h"

namespace parapm {
namespace {

TEST(ChunkedLoops, RangesCoverTheLoopInOrderAtMostChunksOfThemNoneBelowTheMinimum) {
  ChunkedLoops loops(5, 3, 10);
  for (size_t n : {0, 1, 19, 20, 49, 50, 1001}) {
    const auto ranges = testing::loop_ranges(loops, n);
    ASSERT_FALSE(ranges.empty()) << n;
    EXPECT_LE(ranges.size(), 5u) << n;
    EXPECT_EQ(ranges.front().first, 0u) << n;
    EXPECT_EQ(ranges.back().second, n) << n;
    for (size_t i = 1; i < ranges.size(); ++i) EXPECT_EQ(ranges[i].first, ranges[i - 1].second);
    if (ranges.size() > 1) {
      for (const auto& [begin, end] : ranges) EXPECT_GE(end - begin, 10u) << n;
    }
  }
  EXPECT_EQ(testing::loop_ranges(loops, 1001).size(), 5u);
  EXPECT_EQ(testing::loop_ranges(loops, 29).size(), 2u);
  ChunkedLoops plain;
  EXPECT_EQ(testing::loop_ranges(plain, 1000000).size(), 1u);
}

TEST(ChunkedLoops, ALoopCountsItsSlowestChunkOnTheCriticalPath) {
  ChunkedLoops loops(4, 2, 1);
  std::atomic<int> calls{0};
  loops.run(4, [&](size_t begin, size_t) {
    ++calls;
    // Chunk 3 works longest: about 20 ms against 0 for the others.
    if (begin == 3) {
      const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(20);
      while (std::chrono::steady_clock::now() < until) {
      }
    }
  });
  EXPECT_EQ(calls, 4);
  EXPECT_GE(loops.critical_seconds(), 0.02);
  EXPECT_LT(loops.critical_seconds(), loops.seconds());
  const LoopClock clock(loops);
  loops.run(4, [](size_t, size_t) {});
  EXPECT_LT(clock.critical_seconds(), 0.02) << "the loops before the clock are not its";
}

// On threads of their own, all ranges run; on one thread (a one-core machine) the ranges run in
// order and the first exception ends the loop: either way the lowest range's is rethrown.
TEST(ChunkedLoops, TheLowestRangesExceptionIsRethrown) {
  ChunkedLoops loops(4, 4, 1);
  std::atomic<int> calls{0};
  try {
    loops.run(4, [&](size_t begin, size_t) {
      ++calls;
      if (begin >= 1) throw std::runtime_error("range " + std::to_string(begin));
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "range 1");
  }
  EXPECT_GE(calls, 2);
}

// Each range numbers its kept items from the count of the ranges before it: the same numbers as
// one pass in order, whatever the chunks; kept_items gives the old ids alone.
TEST(ChunkedLoops, KeptItemsAreNumberedInOrderAcrossRanges) {
  auto keep = [](size_t i) { return i % 3 != 1 && i != 10; };
  for (unsigned chunks : {1u, 3u, 7u}) {
    ChunkedLoops loops(chunks, chunks, 1);
    const KeptItems kept = number_kept(loops, 20, keep);
    std::vector<uint32_t> old_id;
    std::vector<uint32_t> new_id(20, kNoKey);
    for (size_t i = 0; i < 20; ++i)
      if (keep(i)) {
        new_id[i] = uint32_t(old_id.size());
        old_id.push_back(uint32_t(i));
      }
    EXPECT_EQ(kept.old_id, old_id) << chunks << " chunks";
    EXPECT_EQ(kept.new_id, new_id) << chunks << " chunks";
    EXPECT_EQ(kept_items(loops, 20, keep), old_id) << chunks << " chunks";
  }
}
}  // namespace
}  // namespace parapm
