// ZeroedArray: zeroed elements, small (calloc) and large (mapped), and memory given only to the
// pages written.
#include "util/zeroed_array.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <utility>

#include "util/memory.h"

namespace parapm {
namespace {

TEST(ZeroedArray, SmallAndLargeStartZeroedKeepWhatIsWrittenAndStartAgainZeroed) {
  for (const size_t n : {size_t(2), size_t(1000), size_t(3) << 20}) {
    ZeroedArray<uint64_t> a;
    EXPECT_TRUE(a.empty());
    a.assign_zeroed(n);
    ASSERT_EQ(a.size(), n);
    EXPECT_EQ(a[0], 0u);
    EXPECT_EQ(a[n - 1], 0u);
    a[0] = 7;
    a[n - 1] = 9;
    EXPECT_EQ(a[0], 7u);
    EXPECT_EQ(a[n - 1], 9u);
    ZeroedArray<uint64_t> b(std::move(a));
    EXPECT_TRUE(a.empty());
    ASSERT_EQ(b.size(), n);
    EXPECT_EQ(b[n - 1], 9u);
    b.assign_zeroed(n);  // the same size again: zeroed again
    EXPECT_EQ(b[0], 0u);
    EXPECT_EQ(b[n - 1], 0u);
    a = std::move(b);
    EXPECT_EQ(a.size(), n);
    ZeroedArray<uint64_t> c;
    c.assign_zeroed(n);
    c = std::move(a);  // c's own storage released as it takes a's
    EXPECT_EQ(c.size(), n);
    c.clear();
    EXPECT_TRUE(c.empty());
  }
}

// A table indexed by a whole mesh's ids of which a job writes its region's: 256 MiB of which
// one element in every 16 MiB is written holds far less than 256 MiB.
TEST(ZeroedArray, ALargeArrayTakesMemoryOnlyForThePagesWritten) {
  constexpr size_t kElements = size_t(32) << 20;  // 256 MiB of uint64_t
  const uint64_t start = current_memory_bytes();
  ASSERT_GT(start, 0u);
  ZeroedArray<uint64_t> table;
  table.assign_zeroed(kElements);
  for (size_t i = 0; i < kElements; i += size_t(2) << 20) table[i] = 1;
  const uint64_t now = current_memory_bytes();
  EXPECT_LT(now, start + (uint64_t(16) << 20)) << "bytes resident for 16 elements written";
  EXPECT_EQ(table[kElements - 1], 0u);
}

}  // namespace
}  // namespace parapm
