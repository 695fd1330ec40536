// map_large_blocks_alone: a large block freed goes back to the system at once, even after a
// larger one was freed (which raises glibc's default threshold above it).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "util/memory.h"

namespace parapm {
namespace {

// Fills `bytes` bytes, sums them (so that the block is written and read) and frees them.
uint64_t touch_and_free(size_t bytes) {
  std::vector<unsigned char> block(bytes, 1);
  uint64_t sum = 0;
  for (size_t i = 0; i < bytes; i += 4096) sum += block[i];
  return sum;
}

TEST(LargeBlocks, AFreedLargeBlockLeavesNothingResidentAfterALargerOneWasFreed) {
#if !defined(__GLIBC__)
  GTEST_SKIP() << "glibc's allocator only";
#endif
  map_large_blocks_alone();
  constexpr size_t kMiB = size_t(1) << 20;
  EXPECT_EQ(touch_and_free(24 * kMiB), 24 * kMiB / 4096);
  const uint64_t before = current_memory_bytes();
  ASSERT_GT(before, 0u);
  EXPECT_EQ(touch_and_free(16 * kMiB), 16 * kMiB / 4096);
  EXPECT_LT(current_memory_bytes(), before + 4 * kMiB) << "a freed 16 MiB block stayed resident";
}

}  // namespace
}  // namespace parapm
