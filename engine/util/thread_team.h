// A team of threads for short loops run many times over (one collapse's point projections:
// tens to hundreds of microseconds each). Its threads live as long as the team and wait for
// the next loop, awake for a few milliseconds (yielding their cores) and then asleep, where
// ChunkedLoops starts threads for each loop. A loop is cut into at most `chunks` consecutive
// ranges; range r runs on member r % threads (member 0: the calling thread), so what each
// range computes does not depend on the threads. One loop at a time, from one calling thread.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <thread>
#include <vector>

namespace parapm {

class ThreadTeam {
 public:
  // `threads` 0 or above the hardware's: the hardware's; at most `chunks`. `min_items`: the
  // smallest loop worth the team, for its callers to ask (min_items()).
  ThreadTeam(unsigned chunks, unsigned threads, size_t min_items);
  ~ThreadTeam();
  ThreadTeam(const ThreadTeam&) = delete;
  ThreadTeam& operator=(const ThreadTeam&) = delete;

  unsigned chunks() const { return chunks_; }
  unsigned threads() const { return unsigned(workers_.size()) + 1; }
  size_t min_items() const { return min_items_; }

  // Calls body(begin, end) on consecutive ranges covering [0, n), at most chunks() of them,
  // and returns when all are done. The exception of the lowest range is rethrown; the other
  // ranges still run.
  void run(size_t n, const std::function<void(size_t begin, size_t end)>& body);
  // The same with each range's index (0 ... ranges(n) - 1, in order along [0, n)), for loops
  // whose ranges each fill an output of their own.
  size_t ranges(size_t n) const { return std::min<size_t>(chunks_, n); }
  void run_indexed(size_t n,
                   const std::function<void(size_t range, size_t begin, size_t end)>& body);

  // Wall seconds spent in run(), and what those loops take with a core per chunk: the sum of
  // each loop's slowest range (the parallel build's critical path).
  double seconds() const { return seconds_; }
  double critical_seconds() const { return critical_seconds_; }
  // What the loops took beyond their time with a core per chunk: seconds() less that.
  double saved_seconds() const { return seconds_ - critical_seconds_; }
  // CPU seconds the team's own threads (not the caller) spent in ranges.
  double worker_cpu_seconds() const;

 private:
  void serve(unsigned member);
  void run_ranges(unsigned member);

  const unsigned chunks_;
  const size_t min_items_;
  std::vector<std::thread> workers_;
  std::atomic<uint64_t> generation_{0};  // one more for each loop; the workers wait for it
  std::atomic<unsigned> busy_{0};        // workers still in the current loop
  bool stopping_ = false;                // written before the last generation
  const std::function<void(size_t, size_t, size_t)>* body_ = nullptr;
  size_t n_ = 0;
  size_t ranges_ = 0;
  std::vector<double> range_seconds_;
  std::vector<std::exception_ptr> errors_;
  std::vector<std::atomic<double>> worker_cpu_;  // per worker: worker_cpu_seconds
  double seconds_ = 0;
  double critical_seconds_ = 0;
};

}  // namespace parapm
