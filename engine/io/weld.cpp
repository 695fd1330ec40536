// Welding exactly coincident vertices of a read mesh (formats.h, weld_coincident_vertices),
// and the position hash both welders use (position_hash.h).
#include <bit>
#include <random>
#include <vector>

#include "io/formats.h"
#include "io/position_hash.h"

namespace parapm::io {

uint64_t coordinate_key(double c) { return c == 0 ? 0 : std::bit_cast<uint64_t>(c); }

bool same_place(const Vec3& a, const Vec3& b) {
  return coordinate_key(a[0]) == coordinate_key(b[0]) &&
         coordinate_key(a[1]) == coordinate_key(b[1]) &&
         coordinate_key(a[2]) == coordinate_key(b[2]);
}

uint64_t place_hash(const Vec3& p) {
  static const uint64_t salt =
      (uint64_t(std::random_device{}()) << 32 | std::random_device{}()) | 1;
  uint64_t h = (coordinate_key(p[0]) ^ salt) * 0x9E3779B97F4A7C15ull ^
               std::rotl(coordinate_key(p[1]) * 0xC2B2AE3D27D4EB4Full, 21) ^
               std::rotl(coordinate_key(p[2]) * 0x165667B19E3779F9ull, 42);
  return h ^ (h >> 31);
}

uint64_t weld_coincident_vertices(Mesh& mesh) {
  const size_t n = mesh.positions.size();
  // Per vertex, the first vertex at its place: open addressing on vertex ids, sized for all.
  size_t capacity = 16;
  while (capacity < n * 2) capacity *= 2;
  std::vector<VertexId> slots(capacity, kNoId);
  std::vector<VertexId> first(n);
  uint64_t welded = 0;
  for (VertexId v = 0; v < n; ++v) {
    const Vec3& p = mesh.positions[v];
    for (size_t slot = size_t(place_hash(p)) & (capacity - 1);;
         slot = (slot + 1) & (capacity - 1)) {
      if (slots[slot] == kNoId) {
        slots[slot] = v;
        first[v] = v;
        break;
      }
      if (same_place(mesh.positions[slots[slot]], p)) {
        first[v] = slots[slot];
        ++welded;
        break;
      }
    }
  }
  if (welded == 0) return 0;
  for (Triangle& t : mesh.faces)
    for (VertexId& v : t) v = first[v];
  for (VertexId& v : mesh.wedge_vertex) v = first[v];
  return welded;
}

}  // namespace parapm::io
