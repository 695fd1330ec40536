// ThreadTeam: its loops' ranges do not depend on the threads, every range runs once per loop,
// results are whole after thousands of short loops, exceptions come back, and the timing
// counts a core per chunk.
#include "util/thread_team.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "loop_ranges.h"

namespace parapm {
namespace {

TEST(ThreadTeam, RangesCoverTheLoopOnceAndDoNotDependOnTheThreads) {
  for (const size_t n : {size_t(1), size_t(3), size_t(7), size_t(1000)}) {
    ThreadTeam alone(7, 1, 1);
    const std::vector<std::pair<size_t, size_t>> expected = testing::loop_ranges(alone, n);
    ASSERT_EQ(expected.size(), std::min<size_t>(7, n)) << n;
    size_t next = 0;
    for (const auto& [begin, end] : expected) {
      EXPECT_EQ(begin, next);
      EXPECT_LT(begin, end);
      next = end;
    }
    EXPECT_EQ(next, n);
    for (const unsigned threads : {2u, 3u, 7u}) {
      ThreadTeam team(7, threads, 1);
      EXPECT_EQ(testing::loop_ranges(team, n), expected)
          << n << " items on " << threads << " threads";
    }
  }
  ThreadTeam team(4, 4, 1);
  team.run(0, [](size_t, size_t) { FAIL() << "a loop of no items has no range"; });
}

// An indexed loop's range r is the r-th of run()'s ranges, whatever thread runs it.
TEST(ThreadTeam, IndexedRangesAreNumberedInOrderAlongTheLoop) {
  for (const size_t n : {size_t(1), size_t(5), size_t(1000)}) {
    ThreadTeam team(6, 3, 1);
    const std::vector<std::pair<size_t, size_t>> expected = testing::loop_ranges(team, n);
    ASSERT_EQ(team.ranges(n), expected.size()) << n;
    std::vector<std::pair<size_t, size_t>> seen(expected.size());
    team.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
      seen.at(range) = {begin, end};
    });
    EXPECT_EQ(seen, expected) << n;
  }
}

// Loops of a few microseconds one after the other, as a collapse's projections come: every
// item written by its loop, none lost between loops (the workers wait awake, then asleep).
TEST(ThreadTeam, ThousandsOfShortLoopsEachWriteEveryItem) {
  ThreadTeam team(8, 4, 1);
  std::vector<uint64_t> items(257);
  for (uint64_t loop = 1; loop <= 5000; ++loop) {
    team.run(items.size(), [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) items[i] = loop * 1000 + i;
    });
    for (size_t i = 0; i < items.size(); ++i)
      ASSERT_EQ(items[i], loop * 1000 + i) << "loop " << loop;
  }
}

TEST(ThreadTeam, TheLowestRangesExceptionComesBackAndTheOtherRangesRun) {
  ThreadTeam team(4, 2, 1);
  std::vector<int> ran(4, 0);
  try {
    team.run(4, [&](size_t begin, size_t) {
      ran[begin] = 1;
      if (begin >= 1) throw std::runtime_error("range " + std::to_string(begin));
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "range 1");
  }
  EXPECT_EQ(std::accumulate(ran.begin(), ran.end(), 0), 4);
  std::fill(ran.begin(), ran.end(), 0);  // the team serves the next loop as before
  team.run(4, [&](size_t begin, size_t) { ran[begin] = 1; });
  EXPECT_EQ(std::accumulate(ran.begin(), ran.end(), 0), 4);
}

// On one thread the ranges run one after the other; the critical path counts the slowest of
// each loop only: about a quarter of the wall clock for four equal ranges, all of it if it
// summed them. (The bound leaves room for a loaded machine, where one range of a loop may
// wait out another process's time slice.)
TEST(ThreadTeam, OneThreadCountsTheSlowestRangeOfEachLoop) {
  ThreadTeam team(4, 1, 1);
  EXPECT_EQ(team.threads(), 1u);
  volatile double sink = 0;
  for (int loop = 0; loop < 20; ++loop)
    team.run(4, [&](size_t, size_t) {
      for (int i = 0; i < 200000; ++i) sink = sink + 1e-9 * i;
    });
  EXPECT_GT(team.seconds(), 0);
  EXPECT_LT(team.critical_seconds(), 0.9 * team.seconds());
  EXPECT_EQ(team.worker_cpu_seconds(), 0);
}

}  // namespace
}  // namespace parapm
