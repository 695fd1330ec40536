// Progress reporting and cancellation for long engine work. The worker daemon turns a gRPC
// deadline or cancellation into a CancelToken, and a progress callback into stream messages;
// the CLI draws a progress bar from the same callback.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>

#include "util/error.h"

namespace parapm {

class CancelToken {
 public:
  void cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
  void set_deadline(std::chrono::steady_clock::time_point deadline) {
    deadline_ns_.store(deadline.time_since_epoch().count(), std::memory_order_relaxed);
  }
  // Throws Error(kCancelled) or Error(kDeadlineExceeded); cheap enough to call every few
  // hundred collapses.
  void check() const {
    if (cancelled()) throw Error(ErrorCode::kCancelled, "cancelled");
    const int64_t deadline = deadline_ns_.load(std::memory_order_relaxed);
    if (deadline != 0 && std::chrono::steady_clock::now().time_since_epoch().count() > deadline)
      throw Error(ErrorCode::kDeadlineExceeded, "deadline exceeded");
  }

 private:
  std::atomic<bool> cancelled_{false};
  std::atomic<int64_t> deadline_ns_{0};
};

// Called with the work done so far and the total (same unit, e.g. faces removed; done <= total:
// a last collapse that removes one face more than asked counts as the total); may be empty.
using ProgressCallback = std::function<void(uint64_t done, uint64_t total)>;

}  // namespace parapm
