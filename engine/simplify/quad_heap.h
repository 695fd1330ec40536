// A 4-ary min-heap, the collapse queue's lowest tier (tiered_queue.h). Its sifts are
// memory-bound: with four 16-byte children per node a sift visits half the levels of a
// binary heap and reads one cache line per level (the items are laid out so that every
// node's four children share a line). `Before(x, y)` is true when x must come out before y;
// with a total order the output sequence does not depend on the heap's shape.
#pragma once

#include <algorithm>
#include <cstddef>
#include <new>
#include <vector>

namespace parapm {

// Allocates T arrays whose item 1 starts a 64-byte cache line, so that the children of node i,
// items 4 i + 1 to 4 i + 4, fill one line when sizeof(T) is 16.
template <typename T>
struct ChildLineAllocator {
  using value_type = T;
  static constexpr size_t kLine = 64;
  static constexpr size_t kShift = kLine - sizeof(T) % kLine;  // item 1 at a line's start
  ChildLineAllocator() = default;
  template <typename U>
  ChildLineAllocator(const ChildLineAllocator<U>&) {}
  T* allocate(size_t n) {
    auto* base =
        static_cast<std::byte*>(::operator new(n * sizeof(T) + kLine, std::align_val_t(kLine)));
    return reinterpret_cast<T*>(base + kShift % kLine);
  }
  void deallocate(T* p, size_t) {
    ::operator delete(reinterpret_cast<std::byte*>(p) - kShift % kLine, std::align_val_t(kLine));
  }
  template <typename U>
  bool operator==(const ChildLineAllocator<U>&) const {
    return true;
  }
};

template <typename T, typename Before>
class QuadHeap {
 public:
  bool empty() const { return items_.empty(); }
  size_t size() const { return items_.size(); }
  void clear() { items_.clear(); }
  // Edit freely, then call rebuild().
  std::vector<T, ChildLineAllocator<T>>& items() { return items_; }
  const std::vector<T, ChildLineAllocator<T>>& items() const { return items_; }

  void push(const T& item) {
    size_t i = items_.size();
    items_.push_back(item);
    while (i > 0) {
      const size_t parent = (i - 1) / 4;
      if (!before_(item, items_[parent])) break;
      items_[i] = items_[parent];
      i = parent;
    }
    items_[i] = item;
  }

  const T& top() const { return items_.front(); }  // not empty

  T pop() {
    const T top = items_.front();
    const T last = items_.back();
    items_.pop_back();
    if (!items_.empty()) sift_down(0, last);
    return top;
  }

  void rebuild() {
    if (items_.size() < 2) return;
    for (size_t i = (items_.size() - 2) / 4 + 1; i-- > 0;) sift_down(i, items_[i]);
  }

 private:
  void sift_down(size_t i, const T item) {
    const size_t n = items_.size();
    T* const items = items_.data();
    for (;;) {
      const size_t first = 4 * i + 1;
      size_t best;
      if (first + 4 <= n) {
        // The grandchildren's blocks, one of which the next step reads: fetched while this
        // step compares (the heap is far larger than the cache).
        if (4 * (first + 3) + 1 < n) {
          for (size_t c = 0; c < 4; ++c) __builtin_prefetch(items + 4 * (first + c) + 1);
        } else {
          for (size_t c = first; c < first + 4 && 4 * c + 1 < n; ++c)
            __builtin_prefetch(items + 4 * c + 1);
        }
        // The least of four in pairs; a tie goes to the earlier child, as in a scan.
        const size_t low = before_(items[first + 1], items[first]) ? first + 1 : first;
        const size_t high = before_(items[first + 3], items[first + 2]) ? first + 3 : first + 2;
        best = before_(items[high], items[low]) ? high : low;
      } else if (first < n) {
        best = first;
        for (size_t c = first + 1; c < n; ++c)
          if (before_(items[c], items[best])) best = c;
      } else {
        break;
      }
      if (!before_(items[best], item)) break;
      items[i] = items[best];
      i = best;
    }
    items[i] = item;
  }

  std::vector<T, ChildLineAllocator<T>> items_;
  Before before_;
};

}  // namespace parapm
