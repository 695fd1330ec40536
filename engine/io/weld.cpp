// Welding exactly coincident vertices of a read mesh (formats.h, weld_coincident_vertices),
// and the table of places both welders use (place_table.h).
#include <bit>
#include <random>
#include <vector>

#include "io/formats.h"
#include "io/place_table.h"

namespace parapm::io {
namespace {

// The bit pattern of a coordinate, with -0 folded onto +0 (equal coordinates, different bits).
uint64_t coordinate_key(double c) { return c == 0 ? 0 : std::bit_cast<uint64_t>(c); }

bool same_place(const Vec3& a, const Vec3& b) {
  return coordinate_key(a[0]) == coordinate_key(b[0]) &&
         coordinate_key(a[1]) == coordinate_key(b[1]) &&
         coordinate_key(a[2]) == coordinate_key(b[2]);
}

const uint64_t kSalt = (uint64_t(std::random_device{}()) << 32 | std::random_device{}()) | 1;

uint64_t place_hash(const Vec3& p) {
  uint64_t h = (coordinate_key(p[0]) ^ kSalt) * 0x9E3779B97F4A7C15ull ^
               std::rotl(coordinate_key(p[1]) * 0xC2B2AE3D27D4EB4Full, 21) ^
               std::rotl(coordinate_key(p[2]) * 0x165667B19E3779F9ull, 42);
  return h ^ (h >> 31);
}

}  // namespace

PlaceTable::PlaceTable(const std::vector<Vec3>& positions, uint64_t expected)
    : positions_(positions) {
  size_t capacity = 16;
  while (capacity < expected * 2) capacity *= 2;
  slots_.assign(capacity, kNoId);
  mask_ = capacity - 1;
}

VertexId PlaceTable::first_at(VertexId v) {
  const Vec3& p = positions_[v];
  for (size_t slot = size_t(place_hash(p)) & mask_;; slot = (slot + 1) & mask_) {
    const VertexId listed = slots_[slot];
    if (listed == kNoId) break;
    if (same_place(positions_[listed], p)) return listed;
  }
  if (listed_ == slots_.size() / 2) grow();
  list(v);
  return v;
}

void PlaceTable::list(VertexId v) {
  size_t slot = size_t(place_hash(positions_[v])) & mask_;
  while (slots_[slot] != kNoId) slot = (slot + 1) & mask_;
  slots_[slot] = v;
  ++listed_;
}

void PlaceTable::grow() {
  std::vector<VertexId> old(slots_.size() * 2, kNoId);
  old.swap(slots_);
  mask_ = slots_.size() - 1;
  listed_ = 0;
  for (VertexId v : old)
    if (v != kNoId) list(v);
}

uint64_t weld_coincident_vertices(Mesh& mesh, ChunkedLoops* loops) {
  const size_t n = mesh.positions.size();
  ChunkedLoops one_thread;
  ChunkedLoops& chunks = loops ? *loops : one_thread;
  // Vertices at one place share their hash: each range of hashes (its top 16 bits) finds the
  // first vertex at each of its places, taking its vertices in increasing order.
  constexpr size_t kHashRanges = size_t(1) << 16;
  auto hash_range = [&](size_t v) { return uint32_t(place_hash(mesh.positions[v]) >> 48); };
  const auto vertices_of_range = items_of_ranges(chunks, n, kHashRanges, hash_range);
  std::vector<VertexId> first(n);
  std::vector<uint64_t> welded_in(chunks.ranges(kHashRanges), 0);
  chunks.run_indexed(kHashRanges, [&](size_t range, size_t, size_t) {
    const RangeItems vertices(vertices_of_range, range, n);
    PlaceTable places(mesh.positions, vertices.size());
    for (size_t j = 0; j < vertices.size(); ++j) {
      const VertexId v = vertices[j];
      first[v] = places.first_at(v);
      if (first[v] != v) ++welded_in[range];
    }
  });
  uint64_t welded = 0;
  for (uint64_t w : welded_in) welded += w;
  if (welded == 0) return 0;
  chunks.run(mesh.faces.size(), [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f)
      for (VertexId& v : mesh.faces[f]) v = first[v];
  });
  for (VertexId& v : mesh.wedge_vertex) v = first[v];
  return welded;
}

}  // namespace parapm::io
