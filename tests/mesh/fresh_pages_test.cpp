// fresh_pages.h: a block's pages faulted in by the chunks (resident before any element is
// written), and the helpers' vectors those of resize, assign and copy; memory.h's pages handed
// back.
#include "util/fresh_pages.h"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "util/chunked_loops.h"
#include "util/memory.h"

namespace parapm {
namespace {

// How many of the pages of [data, data + bytes) (a mapping of its own) are resident.
size_t resident_pages(void* data, size_t bytes) {
  const size_t page = size_t(sysconf(_SC_PAGESIZE));
  std::vector<unsigned char> in_core((bytes + page - 1) / page);
  if (mincore(data, bytes, in_core.data()) != 0) return 0;
  size_t resident = 0;
  for (unsigned char c : in_core) resident += c & 1;
  return resident;
}

TEST(FreshPages, EveryPageOfABlockIsFaultedInByTheChunks) {
  const size_t page = size_t(sysconf(_SC_PAGESIZE));
  for (const size_t pages : {size_t(2), size_t(37), size_t(1000)}) {
    for (const unsigned chunks : {1u, 4u, 16u}) {
      const size_t bytes = pages * page;
      void* block =
          mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      ASSERT_NE(block, MAP_FAILED);
      ASSERT_EQ(resident_pages(block, bytes), 0u);
      ChunkedLoops loops(chunks, 2, 1);
      touch_pages(block, bytes, loops);
      EXPECT_EQ(resident_pages(block, bytes), pages) << pages << " pages, " << chunks << " chunks";
      munmap(block, bytes);
    }
  }
  // A block that starts inside a page: the page it starts in is touched too, and nothing
  // before the block is written.
  void* block =
      mmap(nullptr, 64 * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(block, MAP_FAILED);
  auto* bytes = static_cast<unsigned char*>(block);
  ChunkedLoops loops(8, 2, 1);
  touch_pages(bytes + page + 100, 40 * page, loops);
  EXPECT_EQ(resident_pages(block, page), 0u);
  EXPECT_EQ(resident_pages(bytes + page, 41 * page), 41u);
  EXPECT_EQ(resident_pages(bytes + 42 * page, 22 * page), 0u);
  munmap(block, 64 * page);
}

TEST(FreshPages, TheHelpersGiveTheVectorsOfResizeAssignAndCopy) {
  ChunkedLoops loops(16, 2, 1);
  for (const size_t n : {size_t(0), size_t(5), size_t(3) << 18}) {
    std::vector<uint32_t> grown(n / 2);
    std::iota(grown.begin(), grown.end(), 7u);
    std::vector<uint32_t> expected = grown;
    resize_touched(grown, n, loops, 0xabcdu);
    expected.resize(n, 0xabcdu);
    EXPECT_EQ(grown, expected);
    resize_touched(grown, n / 3, loops);  // shrinking: as resize
    expected.resize(n / 3);
    EXPECT_EQ(grown, expected);

    using Triple = std::array<uint32_t, 3>;
    std::vector<Triple> filled = filled_touched(n, Triple{1, 2, 3}, loops);
    EXPECT_EQ(filled, std::vector<Triple>(n, Triple{1, 2, 3}));
    assign_touched(filled, n / 2, Triple{4, 5, 6}, loops);
    EXPECT_EQ(filled, std::vector<Triple>(n / 2, Triple{4, 5, 6}));

    std::string text = "kept";
    resize_touched(text, n + 4, loops);
    EXPECT_EQ(text, "kept" + std::string(n, '\0'));

    std::vector<double> source(n);
    std::iota(source.begin(), source.end(), 0.5);
    std::vector<double> copied = {9.0};
    copy_touched(copied, source, loops);
    EXPECT_EQ(copied, source);
  }
}

// release_pages hands back the pages wholly inside its range only: the bytes around them keep
// their values, the pages inside read as zeros, and a vector's unused capacity released leaves
// its items and its growth as they were.
TEST(FreshPages, ReleasedPagesAreThoseWhollyInsideTheRange) {
  const size_t page = size_t(sysconf(_SC_PAGESIZE));
  const size_t bytes = 8 * page;
  void* block = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(block, MAP_FAILED);
  auto* b = static_cast<unsigned char*>(block);
  for (size_t i = 0; i < bytes; ++i) b[i] = static_cast<unsigned char>(1 + i % 251);
  release_pages(b + 100, b + 5 * page + 7);  // pages 1 to 4
  EXPECT_EQ(resident_pages(b, page), 1u);
  EXPECT_EQ(resident_pages(b + page, 4 * page), 0u);
  EXPECT_EQ(resident_pages(b + 5 * page, 3 * page), 3u);
  for (size_t i = 0; i < bytes; ++i) {
    const bool released = i >= page && i < 5 * page;
    ASSERT_EQ(b[i], released ? 0 : static_cast<unsigned char>(1 + i % 251)) << i;
  }
  release_pages(b + 10, b + page - 10);  // no whole page
  EXPECT_EQ(b[page / 2], static_cast<unsigned char>(1 + (page / 2) % 251));
  munmap(block, bytes);

  std::vector<uint32_t> v;
  v.reserve(64 * page);
  for (uint32_t i = 0; i < 1000; ++i) v.push_back(i * 7);
  release_unused_capacity(v);
  ASSERT_EQ(v.size(), 1000u);
  for (uint32_t i = 0; i < 1000; ++i) ASSERT_EQ(v[i], i * 7);
  for (uint32_t i = 1000; i < 5000; ++i) v.push_back(i * 7);
  for (uint32_t i = 0; i < 5000; ++i) ASSERT_EQ(v[i], i * 7);
}

}  // namespace
}  // namespace parapm
