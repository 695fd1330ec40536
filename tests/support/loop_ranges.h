// The ranges a chunked loop (ChunkedLoops, ThreadTeam: anything with run(n, body(begin, end)))
// cuts [0, n) into, sorted, whatever thread ran each.
#pragma once

#include <algorithm>
#include <cstddef>
#include <mutex>
#include <utility>
#include <vector>

namespace parapm::testing {

template <typename Loops>
std::vector<std::pair<size_t, size_t>> loop_ranges(Loops& loops, size_t n) {
  std::mutex m;
  std::vector<std::pair<size_t, size_t>> ranges;
  loops.run(n, [&](size_t begin, size_t end) {
    std::lock_guard<std::mutex> lock(m);
    ranges.emplace_back(begin, end);
  });
  std::sort(ranges.begin(), ranges.end());
  return ranges;
}

}  // namespace parapm::testing
