// FaceLists: the faces incident to each vertex, for FanMesh. A vertex's list lives inline in
// one 64-byte slot (up to kInline faces, which covers almost every vertex of a triangle mesh:
// the average valence is 6), so that reading or editing it costs one cache line and no
// allocation; longer lists spill to a vector that is recycled when the list is cleared.
// Applying a vsplit touches the lists of vs, vt, vl and vr, at random places in memory: this
// layout is what keeps a million splits well under a second.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mesh/mesh.h"

namespace parapm {

class FaceLists {
 public:
  static constexpr uint32_t kInline = 14;

  size_t size() const { return slots_.size(); }
  void resize(size_t vertices) { slots_.resize(vertices); }  // new lists are empty
  void reserve(size_t vertices) { slots_.reserve(vertices); }
  // Removes the last list, which must be empty.
  void pop_back() { slots_.pop_back(); }

  void prefetch(VertexId v) const { __builtin_prefetch(&slots_[v]); }
  std::span<const FaceId> of(VertexId v) const {
    const Slot& s = slots_[v];
    return {s.spilled == kNone ? s.faces : spill_[s.spilled].data(), s.size};
  }
  void push(VertexId v, FaceId f) {
    Slot& s = slots_[v];
    if (s.spilled == kNone) {
      if (s.size < kInline) {
        s.faces[s.size++] = f;
        return;
      }
      spill(s);
    }
    spill_[s.spilled].push_back(f);
    ++s.size;
  }
  // Keeps the order of the remaining faces.
  template <typename Predicate>
  void erase_if(VertexId v, Predicate remove) {
    Slot& s = slots_[v];
    FaceId* data = s.spilled == kNone ? s.faces : spill_[s.spilled].data();
    uint32_t kept = 0;
    for (uint32_t i = 0; i < s.size; ++i)
      if (!remove(data[i])) data[kept++] = data[i];
    s.size = kept;
    if (s.spilled != kNone) spill_[s.spilled].resize(kept);
  }
  void clear(VertexId v);
  void assign(VertexId v, std::span<const FaceId> faces) {
    clear(v);
    for (FaceId f : faces) push(v, f);
  }

 private:
  static constexpr uint32_t kNone = ~uint32_t(0);
  struct alignas(64) Slot {
    uint32_t size = 0;
    uint32_t spilled = kNone;  // index into spill_, or kNone while the list is inline
    FaceId faces[kInline];
  };
  void spill(Slot& s);

  std::vector<Slot> slots_;
  std::vector<std::vector<FaceId>> spill_;
  std::vector<uint32_t> free_spill_;  // spill_ entries no list uses
};

}  // namespace parapm
