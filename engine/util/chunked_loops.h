// Loops over an index range cut into chunks that run side by side: the passes over a whole
// mesh that a parallel build's master makes (reading, repair, the set-up, the partitions'
// graphs), which would otherwise be one thread's work. Every chunk covers a contiguous range and
// writes only what belongs to it, so a loop's result does not depend on the chunking: one chunk
// gives the same bytes.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "util/fresh_pages.h"

namespace parapm {

class ChunkedLoops {
 public:
  ChunkedLoops() = default;  // one chunk, on the calling thread: a plain loop
  // Each loop cut into at most `chunks` ranges of at least `min_chunk` items (below 4096 a
  // thread costs more than it saves), run on `threads` threads (0: the hardware's).
  ChunkedLoops(unsigned chunks, unsigned threads, size_t min_chunk = 4096);

  unsigned chunks() const { return chunks_; }
  // Calls body(begin, end) on consecutive ranges covering [0, n) and returns when all are
  // done; the exception of the lowest range is rethrown (with one thread, the ranges run on
  // the calling thread, in order, and the first exception ends the loop). One loop at a time.
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

// The items [0, n) of each range of a chunked loop over [0, keys): range r's are those whose
// key_of(i) falls in it, in increasing order (a key of kNoKey: none). Counted and written in
// chunks of items, so that each item's key is read twice in all, not once per range. A loop
// of one range keeps no lists: its range's items are all of [0, n), kNoKey's included.
constexpr uint32_t kNoKey = 0xffffffffu;
class RangeItems {
 public:
  RangeItems(const std::vector<std::vector<uint32_t>>& lists, size_t range, size_t n)
      : list_(lists.empty() ? nullptr : &lists[range]), n_(n) {}
  size_t size() const { return list_ ? list_->size() : n_; }
  uint32_t operator[](size_t j) const { return list_ ? (*list_)[j] : uint32_t(j); }

 private:
  const std::vector<uint32_t>* list_;
  size_t n_;
};
template <class KeyOf>
std::vector<std::vector<uint32_t>> items_of_ranges(ChunkedLoops& loops, size_t n, size_t keys,
                                                   KeyOf key_of) {
  const size_t ranges = loops.ranges(keys);
  if (ranges == 1) return {};
  auto range_of = [&](size_t key) {
    // Range r begins at keys * r / ranges (ChunkedLoops::run_indexed).
    size_t r = key * ranges / keys;
    while (r > 0 && keys * r / ranges > key) --r;
    while (r + 1 < ranges && keys * (r + 1) / ranges <= key) ++r;
    return r;
  };
  std::vector<std::vector<uint32_t>> slots(loops.ranges(n), std::vector<uint32_t>(ranges, 0));
  loops.run_indexed(n, [&](size_t chunk, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const uint32_t key = key_of(i);
      if (key != kNoKey) ++slots[chunk][range_of(key)];
    }
  });
  std::vector<std::vector<uint32_t>> items(ranges);
  for (size_t r = 0; r < ranges; ++r) {
    uint32_t at = 0;
    for (std::vector<uint32_t>& chunk : slots) at += std::exchange(chunk[r], at);
    resize_touched(items[r], at, loops);
  }
  loops.run_indexed(n, [&](size_t chunk, size_t begin, size_t end) {
    std::vector<uint32_t>& next = slots[chunk];
    for (size_t i = begin; i < end; ++i) {
      const uint32_t key = key_of(i);
      if (key == kNoKey) continue;
      const size_t r = range_of(key);
      items[r][next[r]++] = uint32_t(i);
    }
  });
  return items;
}

// The items of [0, n) that keep(i) keeps, numbered in order, in `loops`' chunks (a count per
// range, then the numbers): per item its new number (kNoKey if dropped), and per new number,
// its item.
struct KeptItems {
  std::vector<uint32_t> new_id;
  std::vector<uint32_t> old_id;
};
namespace chunked_detail {
// number_kept(), with the per-item numbers only `with_new_ids`.
template <class Keep>
KeptItems number_kept(ChunkedLoops& loops, size_t n, Keep keep, bool with_new_ids) {
  KeptItems out;
  if (with_new_ids) resize_touched(out.new_id, n, loops, kNoKey);
  std::vector<size_t> first(loops.ranges(n) + 1, 0);  // per range, its first new number
  loops.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
    size_t count = 0;
    for (size_t i = begin; i < end; ++i) count += keep(i) ? 1 : 0;
    first[range + 1] = count;
  });
  for (size_t r = 0; r + 1 < first.size(); ++r) first[r + 1] += first[r];
  resize_touched(out.old_id, first.back(), loops);
  loops.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
    uint32_t next = uint32_t(first[range]);
    for (size_t i = begin; i < end; ++i)
      if (keep(i)) {
        if (with_new_ids) out.new_id[i] = next;
        out.old_id[next++] = uint32_t(i);
      }
  });
  return out;
}
}  // namespace chunked_detail
template <class Keep>
KeptItems number_kept(ChunkedLoops& loops, size_t n, Keep keep) {
  return chunked_detail::number_kept(loops, n, keep, true);
}
// The kept items alone, in order (number_kept's old_id).
template <class Keep>
std::vector<uint32_t> kept_items(ChunkedLoops& loops, size_t n, Keep keep) {
  return std::move(chunked_detail::number_kept(loops, n, keep, false).old_id);
}

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
