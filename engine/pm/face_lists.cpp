// FaceLists (face_lists.h): the blocks of lists that outgrow their slots.
#include "pm/face_lists.h"

#include <algorithm>
#include <cstring>

#include "util/fresh_pages.h"

namespace parapm {

FaceLists::FaceLists(const FaceLists& other) : slots_(other.slots_) {
  for (Slot& s : slots_) {
    if (s.capacity == kInline) continue;
    const FaceId* theirs = s.block;
    s.block = new FaceId[s.capacity];
    std::memcpy(s.block, theirs, s.size * sizeof(FaceId));
  }
}

FaceLists& FaceLists::operator=(const FaceLists& other) {
  if (this != &other) *this = FaceLists(other);
  return *this;
}

FaceLists& FaceLists::operator=(FaceLists&& other) noexcept {
  if (this != &other) {
    free_blocks(0);
    slots_ = std::move(other.slots_);
    other.slots_.clear();
  }
  return *this;
}

void FaceLists::resize(size_t vertices) {
  if (vertices < slots_.size()) free_blocks(vertices);
  slots_.resize(vertices);
}

void FaceLists::resize(size_t vertices, ChunkedLoops& loops) {
  if (vertices < slots_.size()) free_blocks(vertices);
  resize_touched(slots_, vertices, loops);
}

void FaceLists::release(VertexId v) {
  Slot& s = slots_[v];
  if (s.capacity != kInline) delete[] s.block;
  s.capacity = kInline;
  s.size = 0;
}

void FaceLists::grow(Slot& s, uint32_t capacity) {
  FaceId* block = new FaceId[capacity];
  std::memcpy(block, s.data(), s.size * sizeof(FaceId));
  if (s.capacity != kInline) delete[] s.block;
  s.block = block;
  s.capacity = capacity;
}

void FaceLists::free_blocks(size_t from) {
  for (size_t v = from; v < slots_.size(); ++v)
    if (slots_[v].capacity != kInline) delete[] slots_[v].block;
}

}  // namespace parapm
