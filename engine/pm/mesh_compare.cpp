// compare_meshes_exact (mesh_compare.h). Same numbering: a direct walk. Renumbered: positions
// and wedge value tuples are replaced by their rank among the distinct ones (bit patterns,
// sorted), so that a face is six 32-bit numbers and the two face multisets are compared by
// sorting, O(F log F) time and 24 bytes per face.
#include "pm/mesh_compare.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

namespace parapm {

namespace {

using PositionBits = std::array<uint64_t, 3>;

std::string str(uint64_t value) { return std::to_string(value); }

PositionBits bits_of(const Vec3& p) {
  return {std::bit_cast<uint64_t>(p[0]), std::bit_cast<uint64_t>(p[1]),
          std::bit_cast<uint64_t>(p[2])};
}

std::string format(const Vec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.17g, %.17g, %.17g)", p[0], p[1], p[2]);
  return text;
}

std::string format_face(const Triangle& t) {
  return "(" + str(t[0]) + ", " + str(t[1]) + ", " + str(t[2]) + ")";
}

MeshDifference differ(std::string what) { return {false, std::move(what)}; }

// Checks what both comparisons need: layouts, counts, and ids in range (a malformed mesh is a
// difference, never an out-of-bounds read).
MeshDifference check_shape(const Mesh& a, const Mesh& b) {
  if (!(a.layout == b.layout)) return differ("the attribute layouts differ");
  if (a.vertex_count() != b.vertex_count())
    return differ("vertex counts differ: " + str(a.vertex_count()) + " vs " +
                  str(b.vertex_count()));
  if (a.face_count() != b.face_count())
    return differ("face counts differ: " + str(a.face_count()) + " vs " + str(b.face_count()));
  const size_t fpw = size_t(a.layout.floats_per_wedge());
  for (const Mesh* m : {&a, &b}) {
    const char* name = m == &a ? "the first mesh" : "the second mesh";
    for (FaceId f = 0; f < m->face_count(); ++f)
      for (VertexId v : m->faces[f])
        if (v >= m->vertex_count())
          return differ(std::string(name) + ": face " + str(f) + " names vertex " + str(v) +
                        " out of range");
    if (!a.layout.any()) continue;
    if (m->face_wedges.size() != m->face_count() || m->wedge_values.size() < m->wedge_count() * fpw)
      return differ(std::string(name) + ": wedge arrays do not match its faces");
    const size_t wedges = m->wedge_values.size() / fpw;
    for (FaceId f = 0; f < m->face_count(); ++f)
      for (WedgeId w : m->face_wedges[f])
        if (w >= wedges)
          return differ(std::string(name) + ": face " + str(f) + " names wedge " + str(w) +
                        " out of range");
  }
  return {};
}

bool same_values(const Mesh& a, WedgeId wa, const Mesh& b, WedgeId wb, size_t fpw) {
  for (size_t k = 0; k < fpw; ++k)
    if (std::bit_cast<uint32_t>(a.wedge(wa)[k]) != std::bit_cast<uint32_t>(b.wedge(wb)[k]))
      return false;
  return true;
}

MeshDifference compare_same_numbering(const Mesh& a, const Mesh& b) {
  for (VertexId v = 0; v < a.vertex_count(); ++v)
    if (bits_of(a.positions[v]) != bits_of(b.positions[v]))
      return differ("vertex " + str(v) + " is at " + format(a.positions[v]) + " vs " +
                    format(b.positions[v]));
  const size_t fpw = size_t(a.layout.floats_per_wedge());
  for (FaceId f = 0; f < a.face_count(); ++f) {
    const Triangle& ta = a.faces[f];
    const Triangle& tb = b.faces[f];
    int rotation = -1;
    for (int r = 0; r < 3 && rotation < 0; ++r)
      if (ta[0] == tb[r] && ta[1] == tb[(r + 1) % 3] && ta[2] == tb[(r + 2) % 3]) rotation = r;
    if (rotation < 0)
      return differ("face " + str(f) + " is " + format_face(ta) + " vs " + format_face(tb));
    if (!a.layout.any()) continue;
    for (int k = 0; k < 3; ++k)
      if (!same_values(a, a.face_wedges[f][k], b, b.face_wedges[f][(k + rotation) % 3], fpw))
        return differ("face " + str(f) + ", corner at vertex " + str(ta[k]) +
                      ": the attribute values differ");
  }
  return {};
}

// Rank of every position of both meshes among the distinct positions of `a` (b's positions
// are the same multiset when this is called); and of every wedge value tuple of both meshes
// among the distinct tuples of both.
std::vector<uint32_t> position_ranks(const Mesh& m, const std::vector<PositionBits>& distinct) {
  std::vector<uint32_t> rank(m.vertex_count());
  for (VertexId v = 0; v < m.vertex_count(); ++v)
    rank[v] = uint32_t(std::lower_bound(distinct.begin(), distinct.end(), bits_of(m.positions[v])) -
                       distinct.begin());
  return rank;
}

void value_ranks(const Mesh& a, const Mesh& b, std::vector<uint32_t>& rank_a,
                 std::vector<uint32_t>& rank_b) {
  const size_t fpw = size_t(a.layout.floats_per_wedge());
  const size_t wa = a.wedge_values.size() / fpw;
  const size_t wb = b.wedge_values.size() / fpw;
  auto values = [&](size_t i) { return i < wa ? a.wedge(WedgeId(i)) : b.wedge(WedgeId(i - wa)); };
  auto less = [&](size_t i, size_t j) {
    const float* x = values(i);
    const float* y = values(j);
    for (size_t k = 0; k < fpw; ++k) {
      const uint32_t bx = std::bit_cast<uint32_t>(x[k]), by = std::bit_cast<uint32_t>(y[k]);
      if (bx != by) return bx < by;
    }
    return false;
  };
  std::vector<size_t> order(wa + wb);
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(), less);
  rank_a.assign(wa, 0);
  rank_b.assign(wb, 0);
  uint32_t rank = 0;
  for (size_t i = 0; i < order.size(); ++i) {
    if (i > 0 && less(order[i - 1], order[i])) ++rank;
    (order[i] < wa ? rank_a[order[i]] : rank_b[order[i] - wa]) = rank;
  }
}

using FaceKey = std::array<uint32_t, 6>;  // (position rank, value rank) per corner

std::vector<FaceKey> face_keys(const Mesh& m, const std::vector<uint32_t>& position_rank,
                               const std::vector<uint32_t>& value_rank) {
  std::vector<FaceKey> keys(m.face_count());
  for (FaceId f = 0; f < m.face_count(); ++f) {
    FaceKey best{};
    for (int r = 0; r < 3; ++r) {
      FaceKey key;
      for (int k = 0; k < 3; ++k) {
        const int c = (k + r) % 3;
        key[2 * k] = position_rank[m.faces[f][c]];
        key[2 * k + 1] = m.layout.any() ? value_rank[m.face_wedges[f][c]] : 0;
      }
      if (r == 0 || key < best) best = key;
    }
    keys[f] = best;
  }
  std::sort(keys.begin(), keys.end());
  return keys;
}

MeshDifference compare_renumbered(const Mesh& a, const Mesh& b) {
  std::vector<PositionBits> pa(a.vertex_count()), pb(b.vertex_count());
  for (VertexId v = 0; v < a.vertex_count(); ++v) pa[v] = bits_of(a.positions[v]);
  for (VertexId v = 0; v < b.vertex_count(); ++v) pb[v] = bits_of(b.positions[v]);
  std::sort(pa.begin(), pa.end());
  std::sort(pb.begin(), pb.end());
  const auto mismatch = std::mismatch(pa.begin(), pa.end(), pb.begin());
  if (mismatch.first != pa.end()) {
    auto vec = [](const PositionBits& bits) {
      return Vec3{std::bit_cast<double>(bits[0]), std::bit_cast<double>(bits[1]),
                  std::bit_cast<double>(bits[2])};
    };
    return differ("the vertex positions differ: in sorted order the first mesh has " +
                  format(vec(*mismatch.first)) + " where the second has " +
                  format(vec(*mismatch.second)));
  }
  pa.erase(std::unique(pa.begin(), pa.end()), pa.end());
  const std::vector<uint32_t> rank_pa = position_ranks(a, pa), rank_pb = position_ranks(b, pa);
  std::vector<uint32_t> rank_va, rank_vb;
  if (a.layout.any()) value_ranks(a, b, rank_va, rank_vb);
  const std::vector<FaceKey> ka = face_keys(a, rank_pa, rank_va);
  const std::vector<FaceKey> kb = face_keys(b, rank_pb, rank_vb);
  // The first face (in sorted order) that one mesh has more often than the other.
  for (size_t i = 0; i < ka.size(); ++i) {
    if (ka[i] == kb[i]) continue;
    const bool in_a = ka[i] < kb[i];
    const FaceKey& key = in_a ? ka[i] : kb[i];
    std::string corners;
    for (int k = 0; k < 3; ++k) {
      const PositionBits& bits = pa[key[2 * k]];
      corners += (k ? ", " : "") +
                 format(Vec3{std::bit_cast<double>(bits[0]), std::bit_cast<double>(bits[1]),
                             std::bit_cast<double>(bits[2])});
    }
    return differ(std::string("the ") + (in_a ? "first" : "second") +
                  " mesh has a face with corners at " + corners +
                  (a.layout.any() ? " (with its attribute values)" : "") +
                  " that the other lacks or has fewer times");
  }
  return {};
}

}  // namespace

MeshDifference compare_meshes_exact(const Mesh& a, const Mesh& b, bool same_numbering) {
  MeshDifference shape = check_shape(a, b);
  if (!shape.equal) return shape;
  return same_numbering ? compare_same_numbering(a, b) : compare_renumbered(a, b);
}

}  // namespace parapm
