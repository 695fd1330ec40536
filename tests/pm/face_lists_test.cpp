// FaceLists: lists inline and in blocks of their own, edited in place, copied and moved.
#include "pm/face_lists.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "util/chunked_loops.h"

namespace parapm {
namespace {

std::vector<FaceId> list(const FaceLists& lists, VertexId v) {
  const auto faces = lists.of(v);
  return {faces.begin(), faces.end()};
}

std::vector<FaceId> count_up(FaceId from, FaceId to) {
  std::vector<FaceId> out;
  for (FaceId f = from; f < to; ++f) out.push_back(f);
  return out;
}

TEST(FaceLists, ListsGrowPastTheirSlotInOrder) {
  FaceLists lists;
  lists.resize(3);
  const FaceId many = 3 * FaceLists::kInline + 5;
  for (FaceId f = 0; f < many; ++f) lists.push(1, f);
  lists.push(0, 7);
  EXPECT_EQ(list(lists, 1), count_up(0, many));
  EXPECT_EQ(list(lists, 0), std::vector<FaceId>{7});
  EXPECT_TRUE(lists.of(2).empty());
}

// Resized in chunks (pages touched first, for the builds' large meshes): the kept lists stay,
// the new ones are empty, and a list cut off gives its block back (ASan would see a leak).
TEST(FaceLists, ResizedInChunksKeepsTheListsBelow) {
  ChunkedLoops loops(4, 2);
  FaceLists lists;
  lists.resize(3, loops);
  const FaceId many = 2 * FaceLists::kInline + 1;
  for (FaceId f = 0; f < many; ++f) lists.push(0, f), lists.push(2, f);
  lists.resize(2, loops);
  lists.resize(100000, loops);
  EXPECT_EQ(list(lists, 0), count_up(0, many));
  EXPECT_TRUE(lists.of(1).empty());
  EXPECT_TRUE(lists.of(2).empty());
  EXPECT_TRUE(lists.of(99999).empty());
  lists.push(99999, 5);
  EXPECT_EQ(list(lists, 99999), std::vector<FaceId>{5});
}

TEST(FaceLists, EditsInPlace) {
  FaceLists lists;
  lists.resize(2);
  for (VertexId v : {0u, 1u})
    for (FaceId f = 0; f < 20; ++f) lists.push(v, f);  // 0 spills; both lists alike
  for (VertexId v : {0u, 1u}) {
    lists.erase_if(v, [](FaceId f) { return f % 3 == 0; });
    std::vector<FaceId> kept;
    for (FaceId f = 0; f < 20; ++f)
      if (f % 3 != 0) kept.push_back(f);
    EXPECT_EQ(list(lists, v), kept);
    EXPECT_TRUE(lists.remove_swapping_last(v, 4));
    EXPECT_FALSE(lists.remove_swapping_last(v, 4));
    EXPECT_FALSE(lists.remove_swapping_last(v, 99));
    kept[2] = kept.back();  // 4 was third: the last face takes its place
    kept.pop_back();
    EXPECT_EQ(list(lists, v), kept);
  }
  lists.clear(0);
  EXPECT_TRUE(lists.of(0).empty());
  lists.push(0, 5);
  EXPECT_EQ(list(lists, 0), std::vector<FaceId>{5});
  lists.release(1);
  EXPECT_TRUE(lists.of(1).empty());
  lists.assign(1, std::vector<FaceId>{3, 2, 1});
  EXPECT_EQ(list(lists, 1), (std::vector<FaceId>{3, 2, 1}));
}

TEST(FaceLists, CopiesOwnTheirLists) {
  FaceLists lists;
  lists.resize(2);
  for (FaceId f = 0; f < 40; ++f) lists.push(0, f);
  lists.push(1, 1);
  FaceLists copy(lists);
  lists.push(0, 100);
  lists.release(1);
  EXPECT_EQ(list(copy, 0), count_up(0, 40));
  EXPECT_EQ(list(copy, 1), std::vector<FaceId>{1});
  copy = lists;
  EXPECT_EQ(list(copy, 0).size(), 41u);
  EXPECT_TRUE(copy.of(1).empty());
  FaceLists moved(std::move(copy));
  EXPECT_EQ(list(moved, 0).size(), 41u);
  // A vector of slots regrowing moves the lists, their blocks included.
  moved.resize(1000);
  EXPECT_EQ(list(moved, 0).size(), 41u);
  moved.resize(1);
  EXPECT_EQ(list(moved, 0).size(), 41u);
}

TEST(FaceLists, ListsOfDifferentVerticesGrowSideBySide) {
  FaceLists lists;
  lists.resize(64);
  auto fill = [&](VertexId first) {
    for (VertexId v = first; v < 64; v += 2)
      for (FaceId f = 0; f < 50 + v; ++f) lists.push(v, f);
  };
  std::thread even(fill, 0), odd(fill, 1);
  even.join();
  odd.join();
  for (VertexId v = 0; v < 64; ++v) EXPECT_EQ(list(lists, v), count_up(0, 50 + v)) << v;
}

}  // namespace
}  // namespace parapm
