#include "util/chunked_loops.h"

#include <algorithm>
#include <vector>

#include "util/clock.h"
#include "util/job_pool.h"

namespace parapm {

ChunkedLoops::ChunkedLoops(unsigned chunks, unsigned threads, size_t min_chunk)
    : chunks_(std::max(1u, chunks)),
      threads_(threads),
      min_chunk_(std::max<size_t>(1, min_chunk)) {}

size_t ChunkedLoops::ranges(size_t n) const {
  return std::clamp<size_t>(n / min_chunk_, 1, chunks_);
}

void ChunkedLoops::run(size_t n, const std::function<void(size_t, size_t)>& body) {
  run_indexed(n, [&](size_t, size_t begin, size_t end) { body(begin, end); });
}

void ChunkedLoops::run_indexed(size_t n, const std::function<void(size_t, size_t, size_t)>& body) {
  const auto start = std::chrono::steady_clock::now();
  const size_t count = ranges(n);
  if (count == 1) {
    body(0, 0, n);
    const double seconds = seconds_since(start);
    seconds_ += seconds;
    critical_seconds_ += seconds;
    return;
  }
  std::vector<double> range_seconds(count, 0);
  auto range = [&](size_t i) {
    const auto t = std::chrono::steady_clock::now();
    body(i, n * i / count, n * (i + 1) / count);
    range_seconds[i] = seconds_since(t);
  };
  if (pool_threads(threads_, count) == 1) {
    for (size_t i = 0; i < count; ++i) range(i);  // one thread: this one
  } else {
    run_jobs(count, threads_, range);
  }
  seconds_ += seconds_since(start);
  critical_seconds_ += *std::max_element(range_seconds.begin(), range_seconds.end());
}

LoopClock::LoopClock(const ChunkedLoops& loops)
    : loops_(loops),
      start_(std::chrono::steady_clock::now()),
      loops_seconds_(loops.seconds()),
      loops_critical_(loops.critical_seconds()) {}

double LoopClock::critical_seconds() const {
  return seconds_since(start_) - (loops_.seconds() - loops_seconds_) +
         (loops_.critical_seconds() - loops_critical_);
}

}  // namespace parapm
