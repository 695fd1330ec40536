#include "util/fresh_pages.h"

#include <algorithm>
#include <cstdint>

#include "util/chunked_loops.h"

namespace parapm {
namespace {

constexpr size_t kPageBytes = 4096;  // (a larger page is touched more than once: no harm)
constexpr size_t kItemBytes = 64;    // the loop's items: a chunk is at least 4096 of them

}  // namespace

void touch_pages(void* data, size_t bytes, ChunkedLoops& loops) {
  if (bytes < 2 * kPageBytes) return;  // (the fill pays its one or two faults)
  const uintptr_t start = reinterpret_cast<uintptr_t>(data);
  const uintptr_t end = start + bytes;
  // Item i covers [start + i * kItemBytes, ...); each range touches the pages that begin in it.
  loops.run((bytes + kItemBytes - 1) / kItemBytes, [&](size_t first, size_t last) {
    const uintptr_t from = start + first * kItemBytes;
    const uintptr_t to = std::min<uintptr_t>(start + last * kItemBytes, end);
    auto touch = [](uintptr_t at) { *reinterpret_cast<volatile unsigned char*>(at) = 0; };
    uintptr_t page = (from + kPageBytes - 1) & ~uintptr_t(kPageBytes - 1);
    if (first == 0 && from < page) touch(from);  // the page the block begins inside
    for (; page < to; page += kPageBytes) touch(page);
  });
}

void resize_touched(std::string& s, size_t n, ChunkedLoops& loops) {
  if (n > s.capacity()) {
    s.reserve(n);
    touch_pages(s.data() + s.size(), n - s.size(), loops);
  }
  s.resize(n);
}

}  // namespace parapm
