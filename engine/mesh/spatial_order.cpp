#include "mesh/spatial_order.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "mesh/repair.h"

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

// Applies new_index[old] to a per-element array.
template <typename T>
void permute(std::vector<T>& values, const std::vector<uint32_t>& new_index) {
  std::vector<T> out(values.size());
  for (size_t i = 0; i < values.size(); ++i) out[new_index[i]] = std::move(values[i]);
  values = std::move(out);
}

// The elements 0 .. keys.size() - 1 listed by key (each below `key_count`), ties in index
// order: a counting sort, O(n + key_count).
std::vector<uint32_t> stable_order_by(const std::vector<uint32_t>& keys, size_t key_count) {
  std::vector<uint32_t> start(key_count + 1, 0);
  for (uint32_t k : keys) ++start[k + 1];
  for (size_t k = 0; k < key_count; ++k) start[k + 1] += start[k];
  std::vector<uint32_t> order(keys.size());
  for (uint32_t i = 0; i < keys.size(); ++i) order[start[keys[i]]++] = i;
  return order;
}

// new_index[old] from the elements listed in their new order.
std::vector<uint32_t> ranks(const std::vector<uint32_t>& order) {
  std::vector<uint32_t> rank(order.size());
  for (size_t i = 0; i < order.size(); ++i) rank[order[i]] = uint32_t(i);
  return rank;
}

}  // namespace

uint64_t morton_code(const Vec3& p, const Box& box) {
  return spread_bits(quantise(p[0], box.min[0], box.max[0])) |
         spread_bits(quantise(p[1], box.min[1], box.max[1])) << 1 |
         spread_bits(quantise(p[2], box.min[2], box.max[2])) << 2;
}

std::vector<VertexId> spatial_vertex_order(const Mesh& mesh) {
  const Box box = bounding_box(mesh);
  std::vector<std::pair<uint64_t, VertexId>> keyed(mesh.vertex_count());
  for (VertexId v = 0; v < mesh.vertex_count(); ++v)
    keyed[v] = {morton_code(mesh.positions[v], box), v};
  std::sort(keyed.begin(), keyed.end());  // (code, id): ties by id
  std::vector<VertexId> order(keyed.size());
  for (size_t i = 0; i < keyed.size(); ++i) order[i] = keyed[i].second;
  return ranks(order);
}

void order_spatially(RepairedMesh& repaired) {
  Mesh& mesh = repaired.mesh;
  const std::vector<VertexId> new_vertex = spatial_vertex_order(mesh);
  permute(mesh.positions, new_vertex);
  permute(repaired.input_vertex, new_vertex);
  for (Triangle& t : mesh.faces)
    for (VertexId& v : t) v = new_vertex[v];

  // Faces by their first vertex in the new order (the one whose star they are read with
  // first), ties in their previous order. Corners keep their rotation: orientation and the
  // input's corner order (input_face) stay as they were.
  std::vector<uint32_t> first(mesh.face_count());
  for (FaceId f = 0; f < mesh.face_count(); ++f) {
    const Triangle& t = mesh.faces[f];
    first[f] = std::min({t[0], t[1], t[2]});
  }
  const std::vector<FaceId> face_order = stable_order_by(first, mesh.vertex_count());
  const std::vector<FaceId> new_face = ranks(face_order);
  permute(mesh.faces, new_face);
  permute(repaired.input_face, new_face);
  if (!mesh.layout.any()) return;
  permute(mesh.face_wedges, new_face);

  // Wedges by their vertex, ties in their previous order.
  for (VertexId& v : mesh.wedge_vertex) v = new_vertex[v];
  const std::vector<WedgeId> wedge_order = stable_order_by(mesh.wedge_vertex, mesh.vertex_count());
  const std::vector<WedgeId> new_wedge = ranks(wedge_order);
  permute(mesh.wedge_vertex, new_wedge);
  permute(repaired.input_wedge, new_wedge);
  const size_t floats = size_t(mesh.layout.floats_per_wedge());
  std::vector<float> values(mesh.wedge_values.size());
  for (WedgeId w = 0; w < mesh.wedge_count(); ++w)
    std::copy_n(mesh.wedge_values.begin() + ptrdiff_t(w * floats), floats,
                values.begin() + ptrdiff_t(new_wedge[w] * floats));
  mesh.wedge_values = std::move(values);
  for (auto& corners : mesh.face_wedges)
    for (WedgeId& w : corners) w = new_wedge[w];
}

}  // namespace parapm
