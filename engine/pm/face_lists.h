// FaceLists: the faces incident to each vertex, for FanMesh and the simplifier's CollapseMesh.
// A vertex's list lives inline in one 64-byte slot (up to kInline faces, which covers almost
// every vertex of a triangle mesh: the average valence is 6), so that reading or editing it
// costs one cache line and no allocation; a longer list moves to a block of its own, which the
// slot keeps (for the list to grow again) until release(). Applying a vsplit or a collapse
// touches the lists of a few vertices at random places in memory: this layout is what keeps a
// million of them well under a second.
//
// Lists of different vertices may be edited side by side on different threads (each list owns
// its block; nothing is shared between lists).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mesh/mesh.h"

namespace parapm {

class ChunkedLoops;

class FaceLists {
 public:
  static constexpr uint32_t kInline = 14;

  FaceLists() = default;
  FaceLists(const FaceLists& other);
  FaceLists(FaceLists&& other) noexcept : slots_(std::move(other.slots_)) { other.slots_.clear(); }
  FaceLists& operator=(const FaceLists& other);
  FaceLists& operator=(FaceLists&& other) noexcept;
  ~FaceLists() { free_blocks(0); }

  size_t size() const { return slots_.size(); }
  void resize(size_t vertices);  // new lists are empty
  // The same, a new block's pages touched in `loops`' chunks first (fresh_pages.h).
  void resize(size_t vertices, ChunkedLoops& loops);
  void reserve(size_t vertices) { slots_.reserve(vertices); }
  // Removes the last list, which must be empty.
  void pop_back() { resize(slots_.size() - 1); }

  void prefetch(VertexId v) const { __builtin_prefetch(&slots_[v]); }
  std::span<const FaceId> of(VertexId v) const {
    const Slot& s = slots_[v];
    return {s.data(), s.size};
  }
  void push(VertexId v, FaceId f) {
    Slot& s = slots_[v];
    if (s.size == s.capacity) grow(s, 2 * s.capacity);
    s.data()[s.size++] = f;
  }
  // Room for `faces` faces in v's list without a further allocation.
  void reserve_list(VertexId v, uint32_t faces) {
    Slot& s = slots_[v];
    if (faces > s.capacity) grow(s, faces);
  }
  // Keeps the order of the remaining faces.
  template <typename Predicate>
  void erase_if(VertexId v, Predicate remove) {
    Slot& s = slots_[v];
    FaceId* data = s.data();
    uint32_t kept = 0;
    for (uint32_t i = 0; i < s.size; ++i)
      if (!remove(data[i])) data[kept++] = data[i];
    s.size = kept;
  }
  // Removes f, putting the list's last face in its place; false when f is not in the list.
  bool remove_swapping_last(VertexId v, FaceId f) {
    Slot& s = slots_[v];
    FaceId* data = s.data();
    for (uint32_t i = 0; i < s.size; ++i)
      if (data[i] == f) {
        data[i] = data[--s.size];
        return true;
      }
    return false;
  }
  void clear(VertexId v) { slots_[v].size = 0; }  // keeps a block, for the list to grow again
  void release(VertexId v);                       // empties the list and frees its block
  void assign(VertexId v, std::span<const FaceId> faces) {
    clear(v);
    for (FaceId f : faces) push(v, f);
  }

 private:
  // Trivially copyable: a vector of slots moves them as bytes; the blocks are FaceLists's to
  // copy and free.
  struct alignas(64) Slot {
    uint32_t size = 0;
    uint32_t capacity = kInline;  // kInline: the list is inline; above it, in `block`
    union {
      FaceId inline_faces[kInline];
      FaceId* block;
    };
    Slot() {}
    FaceId* data() { return capacity == kInline ? inline_faces : block; }
    const FaceId* data() const { return capacity == kInline ? inline_faces : block; }
  };
  static void grow(Slot& s, uint32_t capacity);
  void free_blocks(size_t from);  // frees the blocks of slots_[from..]

  std::vector<Slot> slots_;
};

}  // namespace parapm
