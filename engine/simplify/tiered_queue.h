// The collapse queue: a priority queue in tiers. A 4-ary heap (quad_heap.h) holds the items
// whose key is at most a threshold; above it, ranges of ascending keys hold the rest,
// unordered, and an open bucket (in blocks) the keys above every range. Items come out in the
// heap's order; when the heap runs out, the next range moves into it; when none is left, the
// open bucket is cut into ranges at the sixteenths of a sample of its keys (the last
// sixteenth staying open). The heap stays small enough for the cache, and an item pushed far
// above the water level costs an append instead of a sift through millions. Items come out
// in exactly the order one heap of them all would give (the `Before` order), as every item
// in a range or the open bucket has a larger key than every item in the heap. Items that died
// while they waited in a range (drop_when) are dropped as it moves into the heap, instead of
// each sifted out of it.
//
// T has a `key` (a float, or an unsigned integer such as a float key's rank: key_rank.h), which
// Before orders first; NaN keys are not allowed.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "simplify/quad_heap.h"

namespace parapm {

template <typename T, typename Before>
class TieredQueue {
 public:
  using Key = std::remove_cvref_t<decltype(std::declval<T>().key)>;
  static constexpr size_t kMinBatch = 4096;  // an open bucket this small goes to the heap whole

  // Items for which `dead` holds are dropped as a range moves into the heap: they would
  // come out only to be skipped (the collapse queue's stale entries).
  void drop_when(std::function<bool(const T&)> dead) { dead_ = std::move(dead); }

  bool empty() const { return size() == 0; }
  size_t size() const { return heap_.size() + bucketed_; }
  void clear() {
    heap_.clear();
    threshold_ = kLowest;
    bounds_.clear();
    ranges_.clear();
    open_.clear();
    next_ = 0;
    bucketed_ = 0;
  }

  void push(const T& item) {
    if (item.key <= threshold_) return heap_.push(item);
    const size_t i = range_of(item.key, next_);
    if (i < bounds_.size())
      ranges_[i].push_back(item);
    else
      push_open(item);
    ++bucketed_;
  }
  const T& top() {  // not empty()
    if (heap_.empty()) refill();
    return heap_.top();
  }
  T pop() {  // not empty()
    if (heap_.empty()) refill();
    return heap_.pop();
  }
  // The item pop() returns next when the heap holds it already (no refill), else null.
  const T* peek() const { return heap_.empty() ? nullptr : &heap_.top(); }

  template <typename Visit>
  void for_each(Visit visit) const {
    for (const T& item : heap_.items()) visit(item);
    for (size_t i = next_; i < ranges_.size(); ++i)
      for (const T& item : ranges_[i]) visit(item);
    for (const Items& block : open_)
      for (const T& item : block) visit(item);
  }
  // Removes every item for which drop(item) holds; returns how many.
  template <typename Drop>
  size_t remove_if(Drop drop) {
    const size_t before = size();
    auto& items = heap_.items();
    items.erase(std::remove_if(items.begin(), items.end(), drop), items.end());
    heap_.rebuild();
    bucketed_ = 0;
    for (size_t i = next_; i < ranges_.size(); ++i) {
      ranges_[i].erase(std::remove_if(ranges_[i].begin(), ranges_[i].end(), drop),
                       ranges_[i].end());
      bucketed_ += ranges_[i].size();
    }
    for (Items& block : open_) {
      block.erase(std::remove_if(block.begin(), block.end(), drop), block.end());
      bucketed_ += block.size();
    }
    return before - size();
  }

 private:
  using Items = std::vector<T, ChildLineAllocator<T>>;  // the heap's array, swapped in whole
  static constexpr size_t kBlock = 8192;                // items per block of the open bucket

  // The range from `first` on whose keys take `key`; bounds_.size(): the open bucket. The
  // first bound not below the key (bounds ascend), found by counting those below it: at most
  // kParts - 1 compares without a branch, where a binary search mispredicts at every step.
  size_t range_of(Key key, size_t first) const {
    size_t i = first;
    for (size_t k = first; k < bounds_.size(); ++k) i += bounds_[k] < key;
    return i;
  }
  void push_open(const T& item) {
    if (open_.empty() || open_.back().size() == kBlock) {
      open_.emplace_back();
      open_.back().reserve(kBlock);
    }
    open_.back().push_back(item);
  }

  // Fills the empty heap from the next non-empty range, cutting the open bucket into ranges
  // when none is left.
  void refill() {
    while (heap_.empty() && bucketed_ > 0) {
      if (next_ == bounds_.size()) {
        cut_open();
        continue;
      }
      Items& range = ranges_[next_];
      threshold_ = bounds_[next_++];
      bucketed_ -= range.size();
      if (dead_) std::erase_if(range, dead_);
      heap_.items().swap(range);
      heap_.rebuild();
      range = Items();
    }
  }

  // Cuts the open bucket into ranges at the keys a sample of it puts at its sixteenths, the
  // last sixteenth staying open; its blocks are freed as they are read, so that the cut
  // holds its items once. An open bucket of at most kMinBatch items goes to the heap whole
  // (and with it every key after it).
  void cut_open() {
    std::vector<Items> blocks = std::move(open_);
    open_.clear();
    size_t count = 0;
    for (const Items& block : blocks) count += block.size();
    bounds_.clear();
    ranges_.clear();
    next_ = 0;
    if (count <= kMinBatch) {
      auto& items = heap_.items();
      for (const Items& block : blocks)
        for (const T& item : block)
          if (!(dead_ && dead_(item))) items.push_back(item);
      heap_.rebuild();
      bucketed_ -= count;
      threshold_ = kHighest;
      return;
    }
    // Every stride-th item (blocks hold fewer than kBlock once remove_if has run).
    const size_t stride = count / kSample;
    sample_.clear();
    size_t block = 0, before = 0;  // the block holding item i * stride, and the items before it
    for (size_t i = 0; i < kSample; ++i) {
      while (i * stride >= before + blocks[block].size()) before += blocks[block++].size();
      sample_.push_back(blocks[block][i * stride - before].key);
    }
    std::sort(sample_.begin(), sample_.end());
    for (size_t k = 1; k < kParts; ++k) {
      const Key bound = sample_[k * kSample / kParts - 1];
      if (bounds_.empty() || bound > bounds_.back()) bounds_.push_back(bound);
    }
    std::vector<size_t> counts(bounds_.size() + 1, 0);
    range_index_.resize(count);
    size_t at = 0;
    for (const Items& block : blocks)
      for (const T& item : block) ++counts[range_index_[at++] = uint8_t(range_of(item.key, 0))];
    ranges_.resize(bounds_.size());
    for (size_t i = 0; i < ranges_.size(); ++i) ranges_[i].reserve(counts[i]);
    at = 0;
    for (Items& block : blocks) {
      for (const T& item : block) {
        const size_t i = range_index_[at++];
        if (i < ranges_.size())
          ranges_[i].push_back(item);
        else
          push_open(item);
      }
      block = Items();
    }
  }

  static constexpr size_t kSample = 1024;
  static constexpr size_t kParts = 16;
  static_assert(kParts <= 256, "a range index is a byte");
  QuadHeap<T, Before> heap_;
  // Below and above every key.
  static constexpr Key kLowest = std::numeric_limits<Key>::has_infinity
                                     ? -std::numeric_limits<Key>::infinity()
                                     : std::numeric_limits<Key>::lowest();
  static constexpr Key kHighest = std::numeric_limits<Key>::has_infinity
                                      ? std::numeric_limits<Key>::infinity()
                                      : std::numeric_limits<Key>::max();
  Key threshold_ = kLowest;  // the heap's keys are at most it
  // ranges_[i] holds the keys in (bounds_[i - 1], bounds_[i]] (the first from threshold_); the
  // open bucket, in blocks, those above every bound.
  std::vector<Key> bounds_;
  std::vector<Items> ranges_;
  std::vector<Items> open_;
  size_t next_ = 0;                   // the first range not yet moved to the heap
  size_t bucketed_ = 0;               // the items in ranges and the open bucket
  std::vector<Key> sample_;           // cut_open's working memory
  std::vector<uint8_t> range_index_;  // and each item's range (kParts fit a byte)
  std::function<bool(const T&)> dead_;
};

}  // namespace parapm
