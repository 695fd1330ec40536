// A fixed-size array whose elements start as all-zero bytes, in pages the system gives memory
// to only when first written: a per-face cache of which a run touches a part (a parallel
// build's master, costing only along the cuts and in the final pass), or a per-thread table
// indexed by the whole mesh's ids of which a subset job's extraction writes its region's,
// holds only that part. A large array is mapped on its own (calloc would take it from the
// allocator's free memory, which it must clear, page by page, whenever a block of that size
// was freed before); a small one comes from calloc.
#pragma once

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>

namespace parapm {

// T: trivially copyable, its all-zero bytes its empty value (an implicit-lifetime type, which
// zeroed storage holds without construction).
template <typename T>
class ZeroedArray {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  ZeroedArray() = default;
  ZeroedArray(const ZeroedArray&) = delete;
  ZeroedArray& operator=(const ZeroedArray&) = delete;
  ZeroedArray(ZeroedArray&& other) noexcept
      : data_(std::exchange(other.data_, nullptr)), size_(std::exchange(other.size_, 0)) {}
  ZeroedArray& operator=(ZeroedArray&& other) noexcept {
    if (this != &other) {
      clear();
      data_ = std::exchange(other.data_, nullptr);
      size_ = std::exchange(other.size_, 0);
    }
    return *this;
  }
  ~ZeroedArray() { clear(); }

  // n zeroed elements in place of the old ones; throws std::bad_alloc.
  void assign_zeroed(size_t n) {
    clear();
    if (n == 0) return;
    if (n > SIZE_MAX / sizeof(T)) throw std::bad_alloc();
    if (n * sizeof(T) >= kMappedBytes) {
      void* mapped =
          mmap(nullptr, n * sizeof(T), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (mapped == MAP_FAILED) throw std::bad_alloc();
      data_ = static_cast<T*>(mapped);
    } else {
      data_ = static_cast<T*>(std::calloc(n, sizeof(T)));
      if (!data_) throw std::bad_alloc();
    }
    size_ = n;
  }
  void clear() {
    if (data_ && size_ * sizeof(T) >= kMappedBytes) {
      munmap(data_, size_ * sizeof(T));
    } else {
      std::free(data_);
    }
    data_ = nullptr;
    size_ = 0;
  }
  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }

 private:
  static constexpr size_t kMappedBytes = size_t(1) << 20;  // from 1 MiB, mapped

  T* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace parapm
