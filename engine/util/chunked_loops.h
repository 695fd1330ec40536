// Loops over an index range cut into chunks that run side by side: the set-up passes over a
// whole mesh, which the parallel build runs before its first round and which would otherwise
// be one thread's work. Every chunk covers a contiguous range and writes only what belongs to
// it, so a loop's result does not depend on the chunking: one chunk gives the same bytes.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>

namespace parapm {

class ChunkedLoops {
 public:
  ChunkedLoops() = default;  // one chunk, on the calling thread: a plain loop
  // Each loop cut into at most `chunks` ranges of at least `min_chunk` items (below 4096 a
  // thread costs more than it saves), run on `threads` threads (0: the hardware's).
  ChunkedLoops(unsigned chunks, unsigned threads, size_t min_chunk = 4096);

  unsigned chunks() const { return chunks_; }
  // Calls body(begin, end) on consecutive ranges covering [0, n) and returns when all are
  // done; the exception of the lowest range is rethrown. One loop at a time.
  void run(size_t n, const std::function<void(size_t begin, size_t end)>& body);
  // The same with each range's index (0 ... ranges(n) - 1, in order along [0, n)), for loops
  // whose ranges each fill an output of their own, joined in order afterwards.
  size_t ranges(size_t n) const;
  void run_indexed(size_t n,
                   const std::function<void(size_t range, size_t begin, size_t end)>& body);

  // Wall seconds spent in run(), and what those loops take with a core per chunk: the sum of
  // each loop's slowest chunk (the critical path the parallel build reports).
  double seconds() const { return seconds_; }
  double critical_seconds() const { return critical_seconds_; }

 private:
  unsigned chunks_ = 1;
  unsigned threads_ = 1;
  size_t min_chunk_ = 1;
  double seconds_ = 0;
  double critical_seconds_ = 0;
};

// A section's time with a core per chunk: the wall seconds since it was made, with the loops
// run meanwhile counted at their critical path.
class LoopClock {
 public:
  explicit LoopClock(const ChunkedLoops& loops);
  double critical_seconds() const;

 private:
  const ChunkedLoops& loops_;
  std::chrono::steady_clock::time_point start_;
  double loops_seconds_, loops_critical_;
};

}  // namespace parapm
