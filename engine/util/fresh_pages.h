// Large blocks are mapped fresh (map_large_blocks_alone, util/memory.h): the first write to each
// page of a new block faults it in, the system clearing the page, which on the machines measured
// costs about three times the write itself. A block filled on one thread pays every fault there.
// These helpers touch a new block's pages in a ChunkedLoops' chunks first, so that the faults
// run side by side and only the fill stays on the calling thread.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace parapm {

class ChunkedLoops;

// Writes a zero byte at the start of each page of [data, data + bytes), chunks side by side:
// raw storage only (the bytes of objects not yet constructed, or about to be overwritten).
void touch_pages(void* data, size_t bytes, ChunkedLoops& loops);

// v.resize(n, value); when that needs a new block, its new elements' pages are touched in
// `loops`' chunks first.
template <class T>
void resize_touched(std::vector<T>& v, size_t n, ChunkedLoops& loops, const T& value = T()) {
  if (n > v.capacity()) {
    v.reserve(n);
    touch_pages(v.data() + v.size(), (n - v.size()) * sizeof(T), loops);
  }
  v.resize(n, value);
}

// The same for a string's bytes (its new ones '\0').
void resize_touched(std::string& s, size_t n, ChunkedLoops& loops);

// v.assign(n, value), a new block's pages touched in `loops`' chunks first.
template <class T>
void assign_touched(std::vector<T>& v, size_t n, const T& value, ChunkedLoops& loops) {
  v.clear();
  resize_touched(v, n, loops, value);
}

// v = from, a new block's pages touched in `loops`' chunks first.
template <class T>
void copy_touched(std::vector<T>& v, const std::vector<T>& from, ChunkedLoops& loops) {
  v.clear();
  if (from.size() > v.capacity()) {
    v.reserve(from.size());
    touch_pages(v.data(), from.size() * sizeof(T), loops);
  }
  v.assign(from.begin(), from.end());
}

// n copies of value, in a block whose pages are touched in `loops`' chunks first.
template <class T>
std::vector<T> filled_touched(size_t n, const T& value, ChunkedLoops& loops) {
  std::vector<T> v;
  resize_touched(v, n, loops, value);
  return v;
}

}  // namespace parapm
