// IdTranslation::near, the exponential search a job's state export translates ids with, must
// answer exactly what the binary search over the whole map answers, whatever the hint.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "simplify/module_state.h"

namespace parapm {
namespace {

TEST(IdTranslation, NearAnswersAsTheWholeSearchFromAnyHint) {
  std::mt19937 random(7);
  for (const size_t size : {0, 1, 2, 3, 5, 17, 64, 300}) {
    // An increasing map with gaps (ids absent from it in between, below and above).
    std::vector<uint32_t> map;
    uint32_t id = std::uniform_int_distribution<uint32_t>(0, 3)(random);
    for (size_t i = 0; i < size; ++i) {
      map.push_back(id);
      id += std::uniform_int_distribution<uint32_t>(1, 4)(random);
    }
    const IdTranslation to_local{&map, true};
    for (uint32_t query = 0; query <= id + 2; ++query)
      for (size_t hint = 0; hint <= size + 1; ++hint)
        ASSERT_EQ(to_local.near(query, hint), to_local(query))
            << "map of " << size << ", id " << query << ", hint " << hint;
    EXPECT_EQ(to_local.near(kNoId, 0), kNoId);
  }
  // The other direction is the map itself.
  const std::vector<uint32_t> map = {4, 9, 12};
  const IdTranslation to_global{&map, false};
  for (uint32_t i = 0; i < map.size(); ++i) EXPECT_EQ(to_global.near(i, 2 - i), map[i]);
}

}  // namespace
}  // namespace parapm
