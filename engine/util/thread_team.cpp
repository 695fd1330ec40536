#include "util/thread_team.h"

#include <algorithm>
#include <chrono>

#include "util/clock.h"
#include "util/job_pool.h"

namespace parapm {
namespace {

// How long a worker waits awake for the next loop (yielding its core to any other thread)
// before it sleeps: the end of a build brings a loop every millisecond or so, and a thread
// woken from sleep is often put on its waker's core, where it shares that core with the
// caller's own range until the scheduler moves it.
constexpr auto kAwake = std::chrono::milliseconds(5);

inline void pause_briefly() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

}  // namespace

ThreadTeam::ThreadTeam(unsigned chunks, unsigned threads, size_t min_items)
    : chunks_(std::max(1u, chunks)),
      min_items_(min_items),
      range_seconds_(chunks_, 0),
      errors_(chunks_),
      worker_cpu_(pool_threads(threads, chunks_) - 1) {
  const unsigned members = pool_threads(threads, chunks_);
  workers_.reserve(members - 1);
  for (unsigned m = 1; m < members; ++m) workers_.emplace_back([this, m] { serve(m); });
}

ThreadTeam::~ThreadTeam() {
  stopping_ = true;
  generation_.fetch_add(1, std::memory_order_release);
  generation_.notify_all();
  for (std::thread& t : workers_) t.join();
}

double ThreadTeam::worker_cpu_seconds() const {
  double sum = 0;
  for (const std::atomic<double>& cpu : worker_cpu_) sum += cpu.load(std::memory_order_relaxed);
  return sum;
}

void ThreadTeam::serve(unsigned member) {
  uint64_t seen = 0;
  for (;;) {
    const auto awake_until = std::chrono::steady_clock::now() + kAwake;
    uint64_t now = generation_.load(std::memory_order_acquire);
    for (int i = 0; now == seen; ++i) {
      if (i < 64) {
        pause_briefly();
      } else if (std::chrono::steady_clock::now() < awake_until) {
        std::this_thread::yield();
      } else {
        generation_.wait(seen, std::memory_order_acquire);
      }
      now = generation_.load(std::memory_order_acquire);
    }
    seen = now;
    if (stopping_) return;
    run_ranges(member);
    if (busy_.fetch_sub(1, std::memory_order_acq_rel) == 1) busy_.notify_one();
  }
}

void ThreadTeam::run_ranges(unsigned member) {
  const double cpu_start = member > 0 ? thread_cpu_seconds() : 0;
  for (size_t r = member; r < ranges_; r += threads()) {
    const auto start = std::chrono::steady_clock::now();
    try {
      (*body_)(r, n_ * r / ranges_, n_ * (r + 1) / ranges_);
    } catch (...) {
      errors_[r] = std::current_exception();
    }
    range_seconds_[r] = seconds_since(start);
  }
  if (member > 0) {
    std::atomic<double>& cpu = worker_cpu_[member - 1];
    cpu.store(cpu.load(std::memory_order_relaxed) + thread_cpu_seconds() - cpu_start,
              std::memory_order_relaxed);
  }
}

void ThreadTeam::run(size_t n, const std::function<void(size_t, size_t)>& body) {
  run_indexed(n, [&body](size_t, size_t begin, size_t end) { body(begin, end); });
}

void ThreadTeam::run_indexed(size_t n, const std::function<void(size_t, size_t, size_t)>& body) {
  if (n == 0) return;
  const auto start = std::chrono::steady_clock::now();
  body_ = &body;
  n_ = n;
  ranges_ = ranges(n);
  const unsigned helpers = unsigned(std::min<size_t>(workers_.size(), ranges_ - 1));
  if (helpers > 0) {
    // Every worker wakes (one generation for all); those without a range return at once.
    busy_.store(unsigned(workers_.size()), std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);
    generation_.notify_all();
  }
  run_ranges(0);
  if (helpers > 0) {
    for (unsigned left = busy_.load(std::memory_order_acquire); left != 0;
         left = busy_.load(std::memory_order_acquire))
      busy_.wait(left, std::memory_order_acquire);
  }
  seconds_ += seconds_since(start);
  critical_seconds_ += *std::max_element(range_seconds_.begin(), range_seconds_.begin() + ranges_);
  for (size_t r = 0; r < ranges_; ++r)
    if (errors_[r]) {
      std::exception_ptr error = errors_[r];
      std::fill(errors_.begin(), errors_.end(), nullptr);
      std::rethrow_exception(error);
    }
}

}  // namespace parapm
