// The collapse queue: a priority queue in tiers. A 4-ary heap (quad_heap.h) holds the items
// whose key is at most a threshold; above it, buckets of ascending key ranges hold the rest,
// unordered, the last one open-ended. Items come out in the heap's order; when the heap runs
// out, the next bucket moves into it; when only the open one is left, it is cut into ranges
// at the sixteenths of a sample of its keys (the last sixteenth staying open). The heap
// stays small enough for the cache, and an item pushed far above the water level costs an
// append instead of a sift through millions. Items come out in exactly the order one heap of
// them all would give (the `Before` order), as every bucketed item has a larger key than
// every item in the heap.
//
// T has a float `cost`, its key, which Before orders first; NaN keys are not allowed.
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

#include "simplify/quad_heap.h"

namespace parapm {

template <typename T, typename Before>
class TieredQueue {
 public:
  static constexpr size_t kMinBatch = 4096;  // an open bucket this small goes to the heap whole

  bool empty() const { return size() == 0; }
  size_t size() const { return heap_.size() + bucketed_; }
  void reserve(size_t n) { open().reserve(n); }
  void clear() {
    heap_.clear();
    threshold_ = -std::numeric_limits<float>::infinity();
    bounds_.clear();
    buckets_.resize(1);
    open().clear();
    next_ = 0;
    bucketed_ = 0;
  }

  void push(const T& item) {
    if (item.cost <= threshold_) return heap_.push(item);
    buckets_[bucket_of(item.cost, next_)].push_back(item);
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

  template <typename Visit>
  void for_each(Visit visit) const {
    for (const T& item : heap_.items()) visit(item);
    for (size_t i = next_; i < buckets_.size(); ++i)
      for (const T& item : buckets_[i]) visit(item);
  }
  // Removes every item for which drop(item) holds; returns how many.
  template <typename Drop>
  size_t remove_if(Drop drop) {
    const size_t before = size();
    auto& items = heap_.items();
    items.erase(std::remove_if(items.begin(), items.end(), drop), items.end());
    heap_.rebuild();
    bucketed_ = 0;
    for (size_t i = next_; i < buckets_.size(); ++i) {
      buckets_[i].erase(std::remove_if(buckets_[i].begin(), buckets_[i].end(), drop),
                        buckets_[i].end());
      bucketed_ += buckets_[i].size();
    }
    return before - size();
  }

 private:
  // buckets_[i] for i < bounds_.size() holds the keys in (bounds_[i - 1], bounds_[i]] (the
  // first from threshold_), the last one (open()) those above every bound.
  using Items = std::vector<T, ChildLineAllocator<T>>;  // the heap's array, swapped in whole
  Items& open() { return buckets_.back(); }

  // The bucket from `first` on whose range holds `key`.
  size_t bucket_of(float key, size_t first) const {
    return size_t(std::lower_bound(bounds_.begin() + first, bounds_.end(), key) - bounds_.begin());
  }

  // Fills the empty heap from the next non-empty bucket, cutting the open one first when
  // it is the only one left.
  void refill() {
    while (heap_.empty() && bucketed_ > 0) {
      if (next_ == bounds_.size()) cut_open();
      Items& bucket = buckets_[next_];
      threshold_ = next_ < bounds_.size() ? bounds_[next_] : std::numeric_limits<float>::infinity();
      bucketed_ -= bucket.size();
      heap_.items().swap(bucket);
      heap_.rebuild();
      bucket = Items();
      if (next_ < bounds_.size()) ++next_;
    }
  }

  // Cuts the open bucket into ranges at the keys a sample of it puts at its sixteenths, the
  // last sixteenth staying open. A bucket of at most kMinBatch items stays whole (and goes
  // to the heap with every key after it).
  void cut_open() {
    Items items = std::move(open());
    bounds_.clear();
    buckets_.clear();
    next_ = 0;
    if (items.size() > kMinBatch) {
      const size_t stride = items.size() / kSample;
      sample_.clear();
      for (size_t i = 0; i < kSample; ++i) sample_.push_back(items[i * stride].cost);
      std::sort(sample_.begin(), sample_.end());
      for (size_t k = 1; k < kParts; ++k) {
        const float bound = sample_[k * kSample / kParts - 1];
        if (bounds_.empty() || bound > bounds_.back()) bounds_.push_back(bound);
      }
    }
    buckets_.resize(bounds_.size() + 1);
    for (auto& bucket : buckets_) bucket.reserve(items.size() / kParts * 5 / 4);
    for (const T& item : items) buckets_[bucket_of(item.cost, 0)].push_back(item);
  }

  static constexpr size_t kSample = 1024;
  static constexpr size_t kParts = 16;
  QuadHeap<T, Before> heap_;
  float threshold_ = -std::numeric_limits<float>::infinity();  // the heap's keys are at most it
  std::vector<float> bounds_;
  std::vector<Items> buckets_ = std::vector<Items>(1);
  size_t next_ = 0;            // the first bucket not yet moved to the heap
  size_t bucketed_ = 0;        // the items in buckets
  std::vector<float> sample_;  // cut_open's working memory
};

}  // namespace parapm
