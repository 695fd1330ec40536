// Welding exactly coincident vertices of a read mesh (formats.h, weld_coincident_vertices).
#include <bit>
#include <random>
#include <vector>

#include "io/formats.h"

namespace parapm::io {
namespace {

// The bit pattern, with -0 folded onto +0 (equal coordinates, different bits).
uint64_t key(double c) { return c == 0 ? 0 : std::bit_cast<uint64_t>(c); }

// Drawn once per process: which slot a place lands in (never the result) changes from run to
// run, so that no file can be made whose places all collide (a quadratic read).
const uint64_t kSalt = (uint64_t(std::random_device{}()) << 32 | std::random_device{}()) | 1;

uint64_t hash_of(const Vec3& p) {
  uint64_t h = (key(p[0]) ^ kSalt) * 0x9E3779B97F4A7C15ull ^
               std::rotl(key(p[1]) * 0xC2B2AE3D27D4EB4Full, 21) ^
               std::rotl(key(p[2]) * 0x165667B19E3779F9ull, 42);
  return h ^ (h >> 31);
}

bool same_place(const Vec3& a, const Vec3& b) {
  return key(a[0]) == key(b[0]) && key(a[1]) == key(b[1]) && key(a[2]) == key(b[2]);
}

}  // namespace

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
    for (size_t slot = size_t(hash_of(p)) & (capacity - 1);; slot = (slot + 1) & (capacity - 1)) {
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
