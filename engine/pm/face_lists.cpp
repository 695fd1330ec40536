// FaceLists (face_lists.h): moving a list out of its slot when it outgrows it, and back.
#include "pm/face_lists.h"

namespace parapm {

void FaceLists::spill(Slot& s) {
  uint32_t index;
  if (!free_spill_.empty()) {
    index = free_spill_.back();
    free_spill_.pop_back();
  } else {
    index = uint32_t(spill_.size());
    spill_.emplace_back();
  }
  spill_[index].assign(s.faces, s.faces + s.size);
  s.spilled = index;
}

void FaceLists::clear(VertexId v) {
  Slot& s = slots_[v];
  if (s.spilled != kNone) {
    spill_[s.spilled].clear();  // keeps its capacity for the next long list
    free_spill_.push_back(s.spilled);
    s.spilled = kNone;
  }
  s.size = 0;
}

}  // namespace parapm
