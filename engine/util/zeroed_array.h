// A fixed-size array whose elements start as all-zero bytes, taken from calloc: for a large
// array the system maps zero pages and gives memory only to the pages first written, so a
// per-face cache of which a run touches a part (a parallel build's master, costing only along
// the cuts and in the final pass) holds only that part.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>

namespace parapm {

// T: trivially copyable, its all-zero bytes its empty value (an implicit-lifetime type, which
// calloc's storage holds without construction).
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
      std::free(data_);
      data_ = std::exchange(other.data_, nullptr);
      size_ = std::exchange(other.size_, 0);
    }
    return *this;
  }
  ~ZeroedArray() { std::free(data_); }

  // n zeroed elements in place of the old ones; throws std::bad_alloc.
  void assign_zeroed(size_t n) {
    clear();
    if (n == 0) return;
    data_ = static_cast<T*>(std::calloc(n, sizeof(T)));
    if (!data_) throw std::bad_alloc();
    size_ = n;
  }
  void clear() {
    std::free(data_);
    data_ = nullptr;
    size_ = 0;
  }
  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }

 private:
  T* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace parapm
