// Which of a star's points (or curve samples) stand for the others when there are too many to
// cost one by one (EnergyOptions::max_sampled_points): about one in `stride`, chosen by a hash
// of the point's id in the whole mesh. By id, not by place in a list: a parallel job's lists
// are in another order than the master's, and both must keep the same points to cost an edge
// alike.
#pragma once

#include <cstddef>
#include <cstdint>

namespace parapm {

inline bool kept_when_thinned(uint32_t id, size_t stride) {
  // splitmix64's finaliser: consecutive ids (neighbours on the surface) spread evenly.
  uint64_t z = uint64_t(id) + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return z % stride == 0;
}

}  // namespace parapm
