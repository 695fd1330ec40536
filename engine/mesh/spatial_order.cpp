#include "mesh/spatial_order.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "mesh/repair.h"
#include "util/fresh_pages.h"

namespace parapm {
namespace {

// The low 21 bits of x, two zero bits after each.
uint64_t spread_bits(uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// x's place in [lo, hi] on 21 bits. Coordinates near the double range make x - lo or hi - lo
// infinite and t NaN: those clamp too (the order is only a matter of speed).
uint64_t quantise(double x, double lo, double hi) {
  constexpr double kMax = double((1u << 21) - 1);
  if (!(hi > lo)) return 0;  // an axis of no extent
  const double t = (x - lo) / (hi - lo);
  if (!(t > 0)) return 0;  // also NaN
  if (!(t < 1)) return uint64_t(kMax);
  return uint64_t(t * kMax);
}

// Applies new_index[old] to a per-element array, in chunks (each writes its own places).
template <typename T>
void permute(std::vector<T>& values, const std::vector<uint32_t>& new_index, ChunkedLoops& loops) {
  std::vector<T> out = filled_touched(values.size(), T(), loops);
  loops.run(values.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) out[new_index[i]] = std::move(values[i]);
  });
  values = std::move(out);
}

// The elements 0 .. keys.size() - 1 listed by key (each below `key_count`), ties in index
// order: a counting sort, O(n + key_count), per range of keys in chunks (items_of_ranges), the
// ranges' lists one after the other.
std::vector<uint32_t> stable_order_by(const std::vector<uint32_t>& keys, size_t key_count,
                                      ChunkedLoops& loops) {
  const auto items =
      items_of_ranges(loops, keys.size(), key_count, [&](size_t i) { return keys[i]; });
  std::vector<size_t> offset(loops.ranges(key_count) + 1, 0);
  for (size_t r = 0; r + 1 < offset.size(); ++r)
    offset[r + 1] = offset[r] + RangeItems(items, r, keys.size()).size();
  std::vector<uint32_t> order = filled_touched<uint32_t>(keys.size(), 0, loops);
  loops.run_indexed(key_count, [&](size_t range, size_t first, size_t last) {
    const RangeItems mine(items, range, keys.size());
    std::vector<size_t> start(last - first + 1, 0);
    for (size_t j = 0; j < mine.size(); ++j) ++start[keys[mine[j]] - first + 1];
    for (size_t k = 0; k < last - first; ++k) start[k + 1] += start[k];
    for (size_t j = 0; j < mine.size(); ++j)
      order[offset[range] + start[keys[mine[j]] - first]++] = mine[j];
  });
  return order;
}

// new_index[old] from the elements listed in their new order.
std::vector<uint32_t> ranks(const std::vector<uint32_t>& order, ChunkedLoops& loops) {
  std::vector<uint32_t> rank = filled_touched<uint32_t>(order.size(), 0, loops);
  loops.run(order.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) rank[order[i]] = uint32_t(i);
  });
  return rank;
}

// The box of the positions, per range then joined (a box's bounds do not depend on the order
// they are found in).
Box bounding_box_in_chunks(const std::vector<Vec3>& positions, ChunkedLoops& loops) {
  if (positions.empty()) return Box{};
  std::vector<Box> boxes(loops.ranges(positions.size()));
  for (Box& box : boxes) box.min = box.max = positions.front();
  loops.run_indexed(positions.size(), [&](size_t range, size_t begin, size_t end) {
    Box& box = boxes[range];
    for (size_t v = begin; v < end; ++v)
      for (int k = 0; k < 3; ++k) {
        box.min[k] = std::min(box.min[k], positions[v][k]);
        box.max[k] = std::max(box.max[k], positions[v][k]);
      }
  });
  Box box = boxes.front();
  for (const Box& b : boxes)
    for (int k = 0; k < 3; ++k) {
      box.min[k] = std::min(box.min[k], b.min[k]);
      box.max[k] = std::max(box.max[k], b.max[k]);
    }
  return box;
}

using Keyed = std::pair<uint64_t, VertexId>;  // (Morton code, id): every key distinct

// `keyed` sorted: with one range, std::sort; with more, a sample sort (each range sorts the
// items between two splitters drawn from a regular sample, the ranges' lists one after the
// other). The keys being distinct, both give the one sorted order.
void sort_keyed(std::vector<Keyed>& keyed, ChunkedLoops& loops) {
  const size_t n = keyed.size(), ranges = loops.ranges(n);
  if (ranges == 1) {
    std::sort(keyed.begin(), keyed.end());
    return;
  }
  constexpr size_t kSamplesPerRange = 64;
  std::vector<Keyed> sample(ranges * kSamplesPerRange);
  for (size_t j = 0; j < sample.size(); ++j) sample[j] = keyed[j * n / sample.size()];
  std::sort(sample.begin(), sample.end());
  std::vector<Keyed> splitters(ranges - 1);  // range r takes the keys below splitters[r]
  for (size_t r = 0; r + 1 < ranges; ++r) splitters[r] = sample[(r + 1) * kSamplesPerRange];
  // Range r of a chunked loop over [0, n) begins at n * r / ranges: the key placing an item
  // in range r's list.
  std::vector<uint32_t> range_key = filled_touched<uint32_t>(n, 0, loops);
  loops.run(n, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const size_t r = size_t(std::upper_bound(splitters.begin(), splitters.end(), keyed[i]) -
                              splitters.begin());
      range_key[i] = uint32_t(n * r / ranges);
    }
  });
  const auto items = items_of_ranges(loops, n, n, [&](size_t i) { return range_key[i]; });
  std::vector<size_t> offset(ranges + 1, 0);
  for (size_t r = 0; r < ranges; ++r) offset[r + 1] = offset[r] + items[r].size();
  std::vector<Keyed> sorted = filled_touched(n, Keyed(), loops);
  loops.run_indexed(n, [&](size_t range, size_t, size_t) {
    const auto out = sorted.begin() + ptrdiff_t(offset[range]);
    for (size_t j = 0; j < items[range].size(); ++j) out[ptrdiff_t(j)] = keyed[items[range][j]];
    std::sort(out, sorted.begin() + ptrdiff_t(offset[range + 1]));
  });
  keyed = std::move(sorted);
}

}  // namespace

uint64_t morton_code(const Vec3& p, const Box& box) {
  return spread_bits(quantise(p[0], box.min[0], box.max[0])) |
         spread_bits(quantise(p[1], box.min[1], box.max[1])) << 1 |
         spread_bits(quantise(p[2], box.min[2], box.max[2])) << 2;
}

std::vector<VertexId> spatial_vertex_order(const Mesh& mesh, ChunkedLoops& loops) {
  const Box box = bounding_box_in_chunks(mesh.positions, loops);
  std::vector<Keyed> keyed = filled_touched(mesh.vertex_count(), Keyed(), loops);
  loops.run(keyed.size(), [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v)
      keyed[v] = {morton_code(mesh.positions[v], box), VertexId(v)};
  });
  sort_keyed(keyed, loops);  // (code, id): ties by id
  std::vector<VertexId> order = filled_touched<VertexId>(keyed.size(), 0, loops);
  loops.run(keyed.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) order[i] = keyed[i].second;
  });
  return ranks(order, loops);
}

std::vector<VertexId> spatial_vertex_order(const Mesh& mesh) {
  ChunkedLoops one_thread;
  return spatial_vertex_order(mesh, one_thread);
}

void order_spatially(RepairedMesh& repaired) {
  ChunkedLoops one_thread;
  order_spatially(repaired, one_thread);
}

void order_spatially(RepairedMesh& repaired, ChunkedLoops& loops) {
  Mesh& mesh = repaired.mesh;
  const std::vector<VertexId> new_vertex = spatial_vertex_order(mesh, loops);
  permute(mesh.positions, new_vertex, loops);
  permute(repaired.input_vertex, new_vertex, loops);
  loops.run(mesh.face_count(), [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f)
      for (VertexId& v : mesh.faces[f]) v = new_vertex[v];
  });

  // Faces by their first vertex in the new order (the one whose star they are read with
  // first), ties in their previous order. Corners keep their rotation: orientation and the
  // input's corner order (input_face) stay as they were.
  std::vector<uint32_t> first = filled_touched<uint32_t>(mesh.face_count(), 0, loops);
  loops.run(mesh.face_count(), [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      const Triangle& t = mesh.faces[f];
      first[f] = std::min({t[0], t[1], t[2]});
    }
  });
  const std::vector<FaceId> face_order = stable_order_by(first, mesh.vertex_count(), loops);
  const std::vector<FaceId> new_face = ranks(face_order, loops);
  permute(mesh.faces, new_face, loops);
  permute(repaired.input_face, new_face, loops);
  if (!mesh.layout.any()) return;
  permute(mesh.face_wedges, new_face, loops);

  // Wedges by their vertex, ties in their previous order.
  loops.run(mesh.wedge_count(), [&](size_t begin, size_t end) {
    for (size_t w = begin; w < end; ++w) mesh.wedge_vertex[w] = new_vertex[mesh.wedge_vertex[w]];
  });
  const std::vector<WedgeId> wedge_order =
      stable_order_by(mesh.wedge_vertex, mesh.vertex_count(), loops);
  const std::vector<WedgeId> new_wedge = ranks(wedge_order, loops);
  permute(mesh.wedge_vertex, new_wedge, loops);
  permute(repaired.input_wedge, new_wedge, loops);
  const size_t floats = size_t(mesh.layout.floats_per_wedge());
  std::vector<float> values = filled_touched<float>(mesh.wedge_values.size(), 0, loops);
  loops.run(mesh.wedge_count(), [&](size_t begin, size_t end) {
    for (size_t w = begin; w < end; ++w)
      std::copy_n(mesh.wedge_values.begin() + ptrdiff_t(w * floats), floats,
                  values.begin() + ptrdiff_t(new_wedge[w] * floats));
  });
  mesh.wedge_values = std::move(values);
  loops.run(mesh.face_wedges.size(), [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f)
      for (WedgeId& w : mesh.face_wedges[f]) w = new_wedge[w];
  });
}

}  // namespace parapm
