// Numbering the distinct (vertex, texcoord, normal) triples of face corners as wedges, in the
// order of first use. Open addressing on a power-of-two table sized for the corner count, so
// the cost is linear however many wedges one vertex has (a hostile file cannot make it
// quadratic). Internal to engine/io.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/mesh.h"

namespace parapm::io {

class WedgeTable {
 public:
  // `max_corners` bounds the number of wedges that will be added.
  explicit WedgeTable(size_t max_corners) {
    size_t capacity = 16;
    while (capacity < max_corners * 2) capacity *= 2;
    slots_.assign(capacity, kNoId);
    mask_ = capacity - 1;
  }

  // The wedge of (v, vt, vn), created when it is new; vt / vn are kNoId when absent.
  WedgeId find_or_add(uint32_t v, uint32_t vt, uint32_t vn) {
    uint64_t h = (uint64_t(v) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(vt) * 0xC2B2AE3D27D4EB4Full) ^
                 (uint64_t(vn) * 0x165667B19E3779F9ull);
    h ^= h >> 29;
    for (size_t slot = size_t(h) & mask_;; slot = (slot + 1) & mask_) {
      const WedgeId w = slots_[slot];
      if (w == kNoId) {
        slots_[slot] = WedgeId(vertex_.size());
        vertex_.push_back(v);
        texcoord_.push_back(vt);
        normal_.push_back(vn);
        return slots_[slot];
      }
      if (vertex_[w] == v && texcoord_[w] == vt && normal_[w] == vn) return w;
    }
  }

  size_t size() const { return vertex_.size(); }
  std::vector<VertexId>& vertices() { return vertex_; }
  uint32_t texcoord(WedgeId w) const { return texcoord_[w]; }
  uint32_t normal(WedgeId w) const { return normal_[w]; }

 private:
  std::vector<WedgeId> slots_;
  size_t mask_ = 0;
  std::vector<VertexId> vertex_;
  std::vector<uint32_t> texcoord_;
  std::vector<uint32_t> normal_;
};

}  // namespace parapm::io
